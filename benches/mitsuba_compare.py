#!/usr/bin/env python3
"""Compares lensview with Mitsuba 3 on flat-colour versions of a scene.

Not run in CI. Needs `pip install mitsuba numpy` (a venv outside the repo).

Flat colour: every object is a constant colour (lensview: ambient 1 under a
white ambient of intensity 1, no diffuse, specular, mirror or lights, so a
surface's radiance is its colour; Mitsuba: an area emitter of that radiance
on a black diffuse surface). The background is the scene's (Mitsuba: a
constant environment). The lens is the one thing that is not flat: lensview's
exact lens, and in Mitsuba a finely tessellated dielectric mesh with exact
sphere normals at its vertices (smooth shading), Mitsuba's `path`
integrator. Only cuboid objects are supported (the scenes compared).

The pixels compared are those the lens changes: where lensview's flat image
with the lens differs from the one without it. Reported: the share of them
whose 8-bit sRGB values agree within 6/255 in every channel.

Usage:
  benches/mitsuba_compare.py LENSVIEW_BINARY[,BINARY2...] SCENE.toml [SCENE.toml ...]
      [--width 240 --height 180 --spp 512 --lv-spp 64 --rings 400 --segments 1600]
      [--mi-max-depth scene|N]  (Mitsuba's max_depth: the scene's + 1 by default)
      [--at-origin] (moves the scene so that its lens is at the origin)
      [--out DIR]   (writes the lensview and Mitsuba images, the misses and
                     the signed difference there)
      [--cache DIR] (keeps each Mitsuba render, keyed by scene and settings)
  Mitsuba renders each scene once; each lensview binary is compared with it.
"""

import argparse
import math
import os
import subprocess
import sys
import tempfile
import tomllib

import numpy as np


def fmt(v):
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return repr(float(v)) if isinstance(v, float) else str(v)
    if isinstance(v, str):
        return '"' + v.replace('"', '\\"') + '"'
    if isinstance(v, list):
        return "[" + ", ".join(fmt(x) for x in v) + "]"
    raise TypeError(v)


def to_toml(d):
    """Writes the subset of TOML lensview scenes use."""
    out = []
    for k, v in d.items():
        if not isinstance(v, (dict, list)) or (isinstance(v, list) and v and not isinstance(v[0], dict)):
            out.append(f"{k} = {fmt(v)}")
    for k, v in d.items():
        if isinstance(v, dict):
            plain = {a: b for a, b in v.items() if not isinstance(b, dict)}
            if plain or not v:
                out.append(f"\n[{k}]")
                out += [f"{a} = {fmt(b)}" for a, b in plain.items()]
            for a, b in v.items():
                if isinstance(b, dict):
                    out.append(f"\n[{k}.{a}]")
                    out += [f"{c} = {fmt(e)}" for c, e in b.items()]
        elif isinstance(v, list) and v and isinstance(v[0], dict):
            for item in v:
                out.append(f"\n[[{k}]]")
                out += [f"{a} = {fmt(b)}" for a, b in item.items()]
    return "\n".join(out) + "\n"


def flat(scene, with_lens=True):
    """The flat-colour version of a parsed scene file."""
    s = {k: v for k, v in scene.items() if k not in ("lights", "ambient", "materials", "objects", "lenses")}
    s["render"] = dict(scene.get("render", {}))
    s["ambient"] = {"color": [1.0, 1.0, 1.0], "intensity": 1.0}
    mats = {}
    for name, m in scene.get("materials", {}).items():
        mats[name] = {"color": m.get("color", [0.7, 0.7, 0.7]), "ambient": 1.0, "diffuse": 0.0, "specular": 0.0}
    mats["__default"] = {"color": [0.7, 0.7, 0.7], "ambient": 1.0, "diffuse": 0.0, "specular": 0.0}
    s["materials"] = mats
    objs = []
    for o in scene.get("objects", []):
        if o.get("type") != "cuboid":
            sys.exit(f"only cuboids are supported, found {o.get('type')}")
        o = dict(o)
        o.setdefault("material", "__default")
        objs.append(o)
    s["objects"] = objs
    if with_lens and scene.get("lenses"):
        s["lenses"] = scene["lenses"]
    return s


def at_lens_origin(scene):
    """The scene moved so that its first lens's centre is the origin.
    Mitsuba offsets a ray spawned at a surface by (1 + max |coordinate|)
    × 1500 ε_float along the normal (`Interaction::offset_p`): near a
    lens's knife edge, where the glass is thinner than that, the refracted
    ray starts beyond the far face and misses it, and a thin ring at the
    silhouette shows what lies straight behind. Small coordinates shrink
    that ring, so what remains is lensview against Mitsuba, not against its
    epsilon."""
    if not scene.get("lenses"):
        return scene
    c = np.array(scene["lenses"][0]["center"], float)
    s = dict(scene)

    def moved(p):
        return (np.array(p, float) - c).tolist()

    s["camera"] = dict(scene["camera"])
    for k in ("position", "look_at"):
        if k in s["camera"]:
            s["camera"][k] = moved(s["camera"][k])
    s["objects"] = [dict(o, position=moved(o.get("position", [0, 0, 0]))) for o in scene.get("objects", [])]
    s["lenses"] = [dict(lens, center=moved(lens["center"])) for lens in scene["lenses"]]
    # Lights: the flat versions have none.
    return s


def rot(deg):
    """lensview's rotation: Ry·Rx·Rz, degrees."""
    x, y, z = (math.radians(a) for a in deg)
    rx = np.array([[1, 0, 0], [0, math.cos(x), -math.sin(x)], [0, math.sin(x), math.cos(x)]])
    ry = np.array([[math.cos(y), 0, math.sin(y)], [0, 1, 0], [-math.sin(y), 0, math.cos(y)]])
    rz = np.array([[math.cos(z), -math.sin(z), 0], [math.sin(z), math.cos(z), 0], [0, 0, 1]])
    return ry @ rx @ rz


def camera_basis(cam):
    pos = np.array(cam["position"], float)
    if "look_at" in cam:
        d = np.array(cam["look_at"], float) - pos
        d /= np.linalg.norm(d)
        pitch = math.degrees(math.asin(max(-1.0, min(1.0, d[1]))))
        yaw = math.degrees(math.atan2(-d[0], -d[2]))
        r = rot([pitch, yaw, 0.0])
    else:
        r = rot(cam.get("rotation", [0, 0, 0]))
    return pos, r @ np.array([0, 0, -1.0]), r @ np.array([0, 1.0, 0])


def lens_mesh(mi, lens, rings, segments):
    """The lens as two spherical caps, exact normals at the vertices."""
    c = np.array(lens["center"], float)
    a = np.array(lens.get("axis", [0, 0, 1]), float)
    a /= np.linalg.norm(a)
    d, r1, r2 = lens["d"], lens["r1"], lens["r2"]
    h = d / 2
    u = np.cross(a, [1.0, 0, 0] if abs(a[0]) < 0.9 else [0, 1.0, 0])
    u /= np.linalg.norm(u)
    v = np.cross(a, u)
    # Rings denser toward the rim, where the caps are steep.
    t = np.linspace(0, 1, rings + 1)
    rho = h * (1 - (1 - t) ** 2)
    phi = np.linspace(0, 2 * math.pi, segments, endpoint=False)
    verts, norms, faces = [], [], []
    for sign, r in ((1.0, r1), (-1.0, r2)):
        centre = c - sign * a * math.sqrt(r * r - h * h)
        base = len(verts)
        for i, p in enumerate(rho):
            z = math.sqrt(max(r * r - p * p, 0.0))
            for f in ([0.0] if i == 0 else phi):
                x = centre + sign * a * z + p * (math.cos(f) * u + math.sin(f) * v)
                verts.append(x)
                norms.append((x - centre) / r)
        # Fan at the vertex, then quads between rings.
        for j in range(segments):
            k = (j + 1) % segments
            tri = (base, base + 1 + j, base + 1 + k)
            faces.append(tri if sign > 0 else tri[::-1])
        for i in range(1, rings):
            r0 = base + 1 + (i - 1) * segments
            r1_ = base + 1 + i * segments
            for j in range(segments):
                k = (j + 1) % segments
                q = [(r0 + j, r1_ + j, r1_ + k), (r0 + j, r1_ + k, r0 + k)]
                for tri in q:
                    faces.append(tri if sign > 0 else tri[::-1])
    verts, norms, faces = np.array(verts), np.array(norms), np.array(faces, dtype=np.uint32)
    # Outward winding: flip triangles whose geometric normal faces in.
    e = np.cross(verts[faces[:, 1]] - verts[faces[:, 0]], verts[faces[:, 2]] - verts[faces[:, 0]])
    inward = np.einsum("ij,ij->i", e, norms[faces[:, 0]]) < 0
    faces[inward] = faces[inward][:, ::-1]
    return verts, norms, faces


def write_ply(path, verts, norms, faces):
    """Binary PLY with per-vertex normals (Mitsuba's `ply` reads them)."""
    head = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(verts)}\n"
        "property float x\nproperty float y\nproperty float z\n"
        "property float nx\nproperty float ny\nproperty float nz\n"
        f"element face {len(faces)}\nproperty list uchar uint vertex_indices\nend_header\n"
    )
    vd = np.hstack([verts, norms]).astype("<f4")
    fd = np.zeros(len(faces), dtype=[("n", "u1"), ("i", "<u4", 3)])
    fd["n"] = 3
    fd["i"] = faces
    with open(path, "wb") as f:
        f.write(head.encode())
        f.write(vd.tobytes())
        f.write(fd.tobytes())


def mitsuba_depth(scene, arg):
    """Mitsuba's `max_depth` for a scene: lensview's `max_depth` counts the
    bounces of a path (a lens pass is 2 + its reflections inside) and then
    takes the radiance of the surface reached; Mitsuba's counts path
    vertices after the camera, the emitter's included, so the same paths
    need one more. `arg`: "scene" (that), or a number (-1: no limit)."""
    if arg == "scene":
        return int(scene.get("render", {}).get("max_depth", 8)) + 1
    return int(arg)


def mitsuba_image(mi, scene, w, h, spp, rings, segments, tmp, max_depth):
    d, tris = mitsuba_scene(mi, scene, w, h, spp, rings, segments, tmp, max_depth)
    img = mi.render(mi.load_dict(d), spp=spp)
    return np.array(img)[:, :, :3], tris


def mitsuba_scene(mi, scene, w, h, spp, rings, segments, tmp, max_depth, surface="diffuse"):
    """Mitsuba's scene dictionary for a flat scene and its lens's triangle
    count. `surface`: the BSDF under each object's emitter, "diffuse"
    (black diffuse: the path integrator samples an emitter from each hit)
    or "delta" (a black smooth conductor: no emitter sample, the path ends
    at the surface, as lensview's flat shading does)."""
    T = mi.ScalarTransform4f
    pos, fwd, up = camera_basis(scene["camera"])
    bg = scene.get("render", {}).get("background", [0.0, 0.0, 0.0])
    d = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth},
        "sensor": {
            "type": "perspective",
            "fov": float(scene["camera"].get("fov", 45.0)),
            "fov_axis": "y",
            "to_world": T().look_at(origin=pos.tolist(), target=(pos + fwd).tolist(), up=up.tolist()),
            "film": {"type": "hdrfilm", "width": w, "height": h, "rfilter": {"type": "box"}, "pixel_format": "rgb"},
            "sampler": {"type": "independent", "sample_count": spp},
        },
        "background": {"type": "constant", "radiance": {"type": "rgb", "value": bg}},
    }
    mats = scene.get("materials", {})
    for i, o in enumerate(scene.get("objects", [])):
        col = mats.get(o.get("material", ""), {}).get("color", [0.7, 0.7, 0.7])
        size = np.array(o.get("size", [1, 1, 1]), float) / 2
        r = rot(o.get("rotation", [0, 0, 0]))
        m = np.eye(4)
        m[:3, :3] = r @ np.diag(size)
        m[:3, 3] = o.get("position", [0, 0, 0])
        d[f"obj{i}"] = {
            "type": "cube",
            "to_world": mi.ScalarTransform4f(m.tolist()),
            "bsdf": black_bsdf(surface),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": col}},
        }
    tris = 0
    for i, lens in enumerate(scene.get("lenses", [])):
        n = lens["n"]
        if isinstance(n, list):
            sys.exit("dispersive lenses are not supported")
        verts, norms, faces = lens_mesh(mi, lens, rings, segments)
        tris += len(faces)
        ply = os.path.join(tmp, f"lens{i}.ply")
        write_ply(ply, verts, norms, faces)
        d[f"lens{i}"] = {
            "type": "ply",
            "filename": ply,
            "face_normals": False,
            "bsdf": {
                "type": "dielectric",
                "int_ior": float(n),
                "ext_ior": 1.0,
                "specular_transmittance": {"type": "rgb", "value": lens.get("tint", [1, 1, 1])},
            },
        }
    return d, tris


def black_bsdf(surface):
    black = {"type": "rgb", "value": [0.0, 0.0, 0.0]}
    if surface == "diffuse":
        return {"type": "diffuse", "reflectance": black}
    if surface == "delta":
        return {"type": "conductor", "specular_reflectance": black}
    raise ValueError(surface)


def srgb8(lin):
    lin = np.clip(lin, 0.0, 1.0)
    s = np.where(lin <= 0.0031308, 12.92 * lin, 1.055 * np.power(lin, 1 / 2.4) - 0.055)
    return np.round(s * 255.0).astype(np.int32)


def lensview_image(binary, scene, w, h, spp, tmp, tag):
    toml = os.path.join(tmp, f"{tag}.toml")
    with open(toml, "w") as f:
        f.write(to_toml(scene))
    out = os.path.join(tmp, f"{tag}.png")
    cmd = [binary, "render", toml, "-o", out, "--width", str(w), "--height", str(h), "--spp", str(spp)]
    subprocess.run(cmd, check=True, stdout=subprocess.DEVNULL)
    from PIL import Image

    return np.array(Image.open(out).convert("RGB")).astype(np.int32)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("scenes", nargs="+")
    ap.add_argument("--width", type=int, default=240)
    ap.add_argument("--height", type=int, default=180)
    ap.add_argument("--spp", type=int, default=512)
    ap.add_argument("--lv-spp", type=int, default=64)
    ap.add_argument("--rings", type=int, default=400)
    ap.add_argument("--segments", type=int, default=1600)
    ap.add_argument(
        "--mi-max-depth",
        default="scene",
        help='Mitsuba\'s max_depth: "scene" (the scene\'s max_depth + 1, the same paths) or a number (-1: none)',
    )
    ap.add_argument(
        "--at-origin", action="store_true", help="move each scene so that its first lens is at the origin (both renderers)"
    )
    ap.add_argument("--out")
    ap.add_argument("--cache", help="keep each Mitsuba image here and reuse it")
    a = ap.parse_args()
    import mitsuba as mi

    # scalar_rgb: the LLVM variants fail to compile their kernels on some CPUs.
    mi.set_variant(os.environ.get("MI_VARIANT", "scalar_rgb"))
    from PIL import Image

    for path in a.scenes:
        with open(path, "rb") as f:
            scene = tomllib.load(f)
        if a.at_origin:
            scene = at_lens_origin(scene)
        with tempfile.TemporaryDirectory() as tmp:
            depth = mitsuba_depth(scene, a.mi_max_depth)
            where = "-origin" if a.at_origin else ""
            key = f"{os.path.basename(path)}{where}-{a.width}x{a.height}-{a.spp}-{a.rings}x{a.segments}-d{depth}.npz"
            cached = os.path.join(a.cache, key) if a.cache else None
            if cached and os.path.exists(cached):
                z = np.load(cached)
                mimg, tris = z["img"], int(z["tris"])
            else:
                mimg, tris = mitsuba_image(
                    mi, flat(scene), a.width, a.height, a.spp, a.rings, a.segments, tmp, depth
                )
                if cached:
                    os.makedirs(a.cache, exist_ok=True)
                    np.savez(cached, img=mimg, tris=tris)
            ms = srgb8(mimg)
            for k, binary in enumerate(a.binary.split(",")):
                lv = lensview_image(binary, flat(scene), a.width, a.height, a.lv_spp, tmp, f"lens{k}")
                bare = lensview_image(binary, flat(scene, False), a.width, a.height, a.lv_spp, tmp, f"bare{k}")
                compare(a, path, binary, lv, bare, ms, tris)


def compare(a, path, binary, lv, bare, ms, tris):
    from PIL import Image

    mask = np.abs(lv - bare).max(axis=2) > 0
    diff = np.abs(lv - ms).max(axis=2)
    ok = (diff <= 6) & mask
    n = int(mask.sum())
    share = 100.0 * ok.sum() / max(n, 1)
    name = os.path.basename(path)
    print(
        f"{name} [{binary}]: {share:.2f} % of {n} lens pixels within 6/255 "
        f"({a.width}x{a.height}, Mitsuba {a.spp} spp, {tris} triangles; lensview {a.lv_spp} spp; "
        f"mean |diff| {diff[mask].mean():.2f}/255)",
        flush=True,
    )
    if a.out:
        os.makedirs(a.out, exist_ok=True)
        stem = os.path.join(a.out, os.path.splitext(name)[0] + "-" + os.path.basename(binary))
        Image.fromarray(lv.astype(np.uint8)).save(stem + "-lensview.png")
        Image.fromarray(ms.astype(np.uint8)).save(stem + "-mitsuba.png")
        bad = np.zeros_like(lv, dtype=np.uint8)
        bad[mask] = 60
        bad[mask & ~ok] = [255, 0, 0]
        Image.fromarray(bad).save(stem + "-misses.png")
        # Signed difference, lensview − Mitsuba: grey 128 = equal, 4 grey
        # levels a level; black outside the pixels compared.
        signed = np.zeros_like(lv, dtype=np.uint8)
        signed[mask] = np.clip(128 + 4 * (lv - ms)[mask], 0, 255).astype(np.uint8)
        Image.fromarray(signed).save(stem + "-signed.png")


if __name__ == "__main__":
    main()
