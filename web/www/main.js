// lensview's page: the wasm App renders in slices between frames and this
// draws its RGBA pixels on a 2D canvas. URL parameters: scene (a preset's
// name, e.g. ?scene=cubes), w, h, spp (0: the scene's), seed.
// window.lensview holds the state the browser test reads.
import init, { App } from "./pkg/lensview_web.js";

const params = new URLSearchParams(location.search);
const num = (k, d) => (params.has(k) ? Number(params.get(k)) : d);
const [width, height] = [num("w", 640), num("h", 480)];
const canvas = document.getElementById("view");
const ctx = canvas.getContext("2d");
const statusLine = document.getElementById("status");
const errorLine = document.getElementById("error");
const state = (window.lensview = { ready: false, done: false, renders: 0, error: "", firstPictureMs: null });

let app = null;
let started = 0;

function restart() {
  state.done = false;
  started = performance.now();
  state.stepMs = 0;
}

function draw() {
  const pixels = new Uint8ClampedArray(app.rgba());
  ctx.putImageData(new ImageData(pixels, app.width(), app.height()), 0, 0);
}

// Renders bands for about 30 ms, draws, and comes back next frame.
function frame() {
  if (!app.done()) {
    const t0 = performance.now();
    while (app.step(1) && performance.now() - t0 < 30) {}
    state.stepMs += performance.now() - t0;
    draw();
    if (state.firstPictureMs === null && app.samplesDone() >= 1) {
      state.firstPictureMs = performance.now();
    }
    if (app.done()) {
      state.renderMs = performance.now() - started;
      state.renders += 1;
      state.done = true;
    }
    statusLine.textContent = `${app.width()}×${app.height()}, ${app.samplesDone()}/${app.spp()} samples` +
      (app.done() ? `, ${(state.renderMs / 1000).toFixed(3)} s` : "…");
  }
  requestAnimationFrame(frame);
}

document.addEventListener("keydown", (e) => {
  if (!app || e.target.tagName === "INPUT") return;
  restartIf(() => app.key(e.code));
});

// Runs `change`; when it starts the picture over, the clocks start over
// (stepMs: time in Rust, the photons of the change included).
function restartIf(change) {
  const t = performance.now();
  if (change()) {
    started = t;
    state.stepMs = performance.now() - t;
    state.done = false;
  }
}

document.getElementById("file").addEventListener("change", async (e) => {
  const file = e.target.files[0];
  if (!file) return;
  const bytes = new Uint8Array(await file.arrayBuffer());
  try {
    restartIf(() => (app.open(file.name, bytes), true));
    errorLine.textContent = "";
    state.error = "";
  } catch (err) {
    errorLine.textContent = String(err);
    state.error = String(err);
  }
  e.target.value = "";
});

async function main() {
  await init();
  restart();
  try {
    app = new App(params.get("scene"), width, height, num("spp", 0), num("seed", 0));
    state.stepMs = performance.now() - started;
  } catch (err) {
    errorLine.textContent = String(err);
    state.error = String(err);
    statusLine.textContent = "";
    return;
  }
  canvas.width = app.width();
  canvas.height = app.height();
  canvas.focus();
  state.ready = true;
  state.sceneToml = () => app.sceneToml();
  requestAnimationFrame(frame);
}

main();
