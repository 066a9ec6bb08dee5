//! Linear-light OpenEXR output: a single-part scanline file, one line a
//! chunk, uncompressed, channels B, G, R as 32-bit floats (the OpenEXR 2
//! file layout: magic, version, header attributes, line offset table,
//! lines). Written here rather than with a crate: the layout is a few
//! dozen bytes of header, and the values go in unchanged.

use crate::color::Rgb;

/// `v/1\x01`: the OpenEXR magic number.
const MAGIC: [u8; 4] = [0x76, 0x2f, 0x31, 0x01];
/// Version 2, single-part scanline, short names.
const VERSION: [u8; 4] = [2, 0, 0, 0];
/// The `pixelType` of a 32-bit float channel.
const FLOAT: i32 = 2;

/// One header attribute: name, type name, size and value.
fn attribute(out: &mut Vec<u8>, name: &str, kind: &str, value: &[u8]) {
    out.extend_from_slice(name.as_bytes());
    out.push(0);
    out.extend_from_slice(kind.as_bytes());
    out.push(0);
    out.extend_from_slice(&(value.len() as i32).to_le_bytes());
    out.extend_from_slice(value);
}

/// `xMin, yMin, xMax, yMax` of a `width × height` image.
fn window(width: u32, height: u32) -> Vec<u8> {
    [0, 0, width as i32 - 1, height as i32 - 1]
        .iter()
        .flat_map(|v| v.to_le_bytes())
        .collect()
}

/// The file's bytes for `pixels` (row-major, top row first, linear RGB),
/// each channel the `f32` nearest the value, unclamped.
pub fn encode(width: u32, height: u32, pixels: &[Rgb]) -> Vec<u8> {
    let mut out = Vec::new();
    out.extend_from_slice(&MAGIC);
    out.extend_from_slice(&VERSION);
    let mut channels = Vec::new();
    for name in ["B", "G", "R"] {
        channels.extend_from_slice(name.as_bytes());
        channels.push(0);
        channels.extend_from_slice(&FLOAT.to_le_bytes());
        channels.extend_from_slice(&[0, 0, 0, 0]); // pLinear, reserved
        channels.extend_from_slice(&1i32.to_le_bytes());
        channels.extend_from_slice(&1i32.to_le_bytes());
    }
    channels.push(0);
    attribute(&mut out, "channels", "chlist", &channels);
    attribute(&mut out, "compression", "compression", &[0]);
    attribute(&mut out, "dataWindow", "box2i", &window(width, height));
    attribute(&mut out, "displayWindow", "box2i", &window(width, height));
    attribute(&mut out, "lineOrder", "lineOrder", &[0]);
    attribute(&mut out, "pixelAspectRatio", "float", &1f32.to_le_bytes());
    attribute(&mut out, "screenWindowCenter", "v2f", &[0; 8]);
    attribute(&mut out, "screenWindowWidth", "float", &1f32.to_le_bytes());
    out.push(0);
    let w = width as usize;
    let line_bytes = 3 * 4 * w;
    let table = out.len();
    let first = table + 8 * height as usize;
    for y in 0..height as usize {
        let at = (first + y * (8 + line_bytes)) as u64;
        out.extend_from_slice(&at.to_le_bytes());
    }
    for (y, row) in pixels.chunks(w.max(1)).take(height as usize).enumerate() {
        out.extend_from_slice(&(y as i32).to_le_bytes());
        out.extend_from_slice(&(line_bytes as i32).to_le_bytes());
        for channel in [|c: &Rgb| c.z, |c: &Rgb| c.y, |c: &Rgb| c.x] {
            for c in row {
                out.extend_from_slice(&(channel(c) as f32).to_le_bytes());
            }
        }
    }
    out
}
