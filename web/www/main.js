// lensview's page: a render worker (worker.js, holding the wasm App) posts
// pictures and this draws them on a 2D canvas, forwards keys and scene files
// (file input or drop) and saves the scene and the picture. URL parameters:
// scene (a preset's name, e.g. ?scene=cubes), w, h, spp (0: the scene's),
// seed. window.lensview holds the state the browser test reads. The editing
// panel (panel.js) shows the rows the worker's App describes and sends
// values back; Undo/Redo and Ctrl+Z / Ctrl+Shift+Z step the scene's history.
import { createPanel } from "./panel.js";

const params = new URLSearchParams(location.search);
const num = (k, d) => (params.has(k) ? Number(params.get(k)) : d);
const [width, height] = [num("w", 640), num("h", 480)];
const canvas = document.getElementById("view");
const ctx = canvas.getContext("2d");
const statusLine = document.getElementById("status");
const errorLine = document.getElementById("error");
const messageLine = document.getElementById("message");
const overlay = document.getElementById("overlay");
const state = (window.lensview = {
  ready: false,
  retried: params.has("retry"),
  done: false,
  renders: 0,
  error: "",
  message: "",
  firstPictureMs: null,
  isolated: self.crossOriginIsolated,
  panel: null, // the panel shown (App.panel's JSON, parsed)
});

// Threads need cross-origin isolation (SharedArrayBuffer); say so without.
// `threads=N` caps them (the page sets threads=1 itself after its thread
// pool twice failed to start: below).
const threads = self.crossOriginIsolated ? Math.max(1, num("threads", navigator.hardwareConcurrency || 1)) : 1;
if (!self.crossOriginIsolated) {
  document.getElementById("note").textContent = "one thread: serve with COOP/COEP for threads";
} else if (threads === 1 && params.has("threads")) {
  document.getElementById("note").textContent = "one thread: the thread pool did not start";
}

// wasm-bindgen-rayon's thread pool sometimes never starts (Firefox ESR 153,
// about one page load in 30 here: initThreadPool's promise never settles,
// no error). Stuck there for START_LIMIT_MS, the page loads itself again;
// stuck a second time, it loads on one thread (and says so).
const START_LIMIT_MS = 15000;
function stuckStarting() {
  if (state.ready || state.starting !== "threads") return;
  const next = new URLSearchParams(location.search);
  if (next.has("retry")) next.set("threads", "1");
  else next.set("retry", "1");
  location.search = next.toString();
}

const worker = new Worker("worker.js", { type: "module" });
const showPanel = createPanel(document.getElementById("panel"), (m) => worker.postMessage(m));
let picture = 0; // the picture the worker renders now (its generation)
let lastDone = 0; // the last picture seen finished
let shownPicture = 0; // the picture the last frame drawn showed
let sceneName = params.get("scene") || "scene";
const replies = new Map(); // sceneToml requests by id
let nextId = 0;

function showError(text) {
  errorLine.textContent = text;
  state.error = text;
}

function drawFrame(f) {
  if (f.generation < picture) return; // posted before the last change
  ctx.putImageData(new ImageData(new Uint8ClampedArray(f.rgba.buffer), f.width, f.height), 0, 0);
  if (f.generation !== shownPicture) {
    // The first frame of a new picture: the time from the change (a key,
    // a file, the start) to it.
    shownPicture = f.generation;
    state.reactMs = f.renderMs;
  }
  if (state.firstFrameMs === undefined) state.firstFrameMs = performance.now();
  if (state.firstPictureMs === null && f.samplesDone >= 1) {
    state.firstPictureMs = performance.now();
  }
  state.stage = f.stage;
  if (f.done && f.generation !== lastDone) {
    lastDone = f.generation;
    state.renders += 1;
    [state.renderMs, state.previewMs, state.samplesMs] = [f.renderMs, f.previewMs, f.samplesMs];
  }
  state.done = f.done;
  statusLine.textContent =
    `${f.width}×${f.height}, ${f.stage} of ${f.spp} spp` +
    (f.done ? `, ${(f.renderMs / 1000).toFixed(3)} s` : "…") +
    `, ${state.threads} thread${state.threads === 1 ? "" : "s"}`;
  // As the desktop's overlay: the stage, then the time a sample took.
  const perSample = f.samplesDone > 0 ? `${(f.samplesMs / f.samplesDone).toFixed(1)} ms a sample` : "previews";
  overlay.textContent =
    `${f.stage} of ${f.spp} spp${f.done ? " (done)" : ""}, ${f.renderMs.toFixed(0)} ms\n` +
    `${perSample}, ${state.threads} thread${state.threads === 1 ? "" : "s"}` +
    (self.crossOriginIsolated ? "" : " (not isolated)");
}

// A change that restarts the picture (a key, a panel edit, undo, redo).
function restarted(message) {
  picture += 1;
  state.done = false;
  messageLine.textContent = message;
  state.message = message;
}

worker.onmessage = ({ data: d }) => {
  if (d.type === "frame") {
    drawFrame(d);
  } else if (d.type === "ready") {
    canvas.width = d.width;
    canvas.height = d.height;
    canvas.focus();
    picture = 1;
    state.threads = d.threads;
    state.ready = true;
    // Isolated, but the browser made no shared memory: the worker loaded
    // the one-thread build (WebKitGTK without useSharedArrayBuffer).
    if (d.threads === 1 && threads > 1) {
      document.getElementById("note").textContent = "one thread: this browser gives no shared memory";
    }
  } else if (d.type === "key") {
    if (d.changed) restarted(d.message);
    messageLine.textContent = d.message;
    state.message = d.message;
  } else if (d.type === "edited") {
    // A panel edit, undo or redo that the document took.
    showError("");
    if (d.changed) restarted(d.message);
    messageLine.textContent = d.message;
    state.message = d.message;
  } else if (d.type === "panel") {
    state.panel = JSON.parse(d.json);
    state.panels = (state.panels || 0) + 1; // panels shown (the test waits on it)
    showPanel(state.panel);
  } else if (d.type === "opened") {
    picture += 1;
    state.done = false;
    sceneName = d.name.replace(/\.toml$/, "");
    showError("");
  } else if (d.type === "starting") {
    // Where the worker's start is (the module, its threads, the scene).
    state.starting = d.step;
    statusLine.textContent = `loading: ${d.step}…`;
    if (d.step === "threads") setTimeout(stuckStarting, START_LIMIT_MS);
  } else if (d.type === "error") {
    showError(d.text);
    if (!state.ready) statusLine.textContent = "";
  } else if (d.type === "toml") {
    replies.get(d.id)(d.text);
    replies.delete(d.id);
  }
};
worker.onerror = (e) => showError(`error: the render worker failed: ${e.message}`);

// The scene now (camera and lens edits included) as a scene file.
state.sceneToml = () =>
  new Promise((resolve) => {
    nextId += 1;
    replies.set(nextId, resolve);
    worker.postMessage({ type: "toml", id: nextId });
  });

const BROWSER_KEYS = new Set(["ArrowUp", "ArrowDown", "ArrowLeft", "ArrowRight", "PageUp", "PageDown", "F9", "Quote", "Slash"]);
document.addEventListener("keydown", (e) => {
  if (!state.ready || e.target.tagName === "INPUT" || e.target.tagName === "SELECT") return;
  if ((e.ctrlKey || e.metaKey) && (e.code === "KeyZ" || e.code === "KeyY")) {
    // Ctrl+Z undoes; Ctrl+Shift+Z and Ctrl+Y redo (the scene's history).
    e.preventDefault();
    worker.postMessage({ type: e.shiftKey || e.code === "KeyY" ? "redo" : "undo" });
    return;
  }
  if (e.ctrlKey || e.metaKey || e.altKey) return;
  // Keys the browser would also act on (scroll the page, quick find).
  if (BROWSER_KEYS.has(e.code)) e.preventDefault();
  worker.postMessage({ type: "key", code: e.code });
});

async function open(file) {
  const bytes = new Uint8Array(await file.arrayBuffer());
  worker.postMessage({ type: "open", name: file.name, bytes }, [bytes.buffer]);
}

const fileInput = document.getElementById("file");
fileInput.addEventListener("change", async () => {
  if (fileInput.files[0]) await open(fileInput.files[0]);
  fileInput.value = "";
});
document.addEventListener("dragover", (e) => e.preventDefault());
document.addEventListener("drop", async (e) => {
  e.preventDefault();
  const file = e.dataTransfer.files[0];
  if (file) await open(file);
});

function download(name, blob) {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(blob);
  a.download = name;
  a.click();
  setTimeout(() => URL.revokeObjectURL(a.href), 10000);
}
document.getElementById("save-scene").addEventListener("click", async () => {
  const text = await state.sceneToml();
  download(`${sceneName}.toml`, new Blob([text], { type: "application/toml" }));
});
document.getElementById("save-png").addEventListener("click", () => {
  canvas.toBlob((png) => download(`${sceneName}.png`, png), "image/png");
});

worker.postMessage({
  type: "start",
  scene: params.get("scene"),
  width,
  height,
  spp: num("spp", 0),
  seed: num("seed", 0),
  threads,
});

// Mouse-look as on the desktop: click the picture to lock the pointer (Esc
// releases it); its movement turns the camera (the library's flight::look,
// the desktop drag's degrees a pixel). One look is in the worker at a time:
// movement meanwhile is summed and sent when it answers, so a fast mouse
// does not queue reprojections. Releasing the pointer ends the gesture
// (one undo step).
const look = { dx: 0, dy: 0, waiting: false };
function sendLook() {
  if (look.waiting || (look.dx === 0 && look.dy === 0)) return;
  worker.postMessage({ type: "look", dx: look.dx, dy: look.dy });
  [look.dx, look.dy, look.waiting] = [0, 0, true];
}
// What pointer-locked movement does (the browser test calls it: headless
// browsers give no pointer lock).
state.lookBy = (dx, dy) => {
  look.dx += dx;
  look.dy += dy;
  sendLook();
};
canvas.addEventListener("click", () => {
  if (state.ready && document.pointerLockElement !== canvas) canvas.requestPointerLock();
});
document.addEventListener("mousemove", (e) => {
  if (document.pointerLockElement === canvas) state.lookBy(e.movementX, e.movementY);
});
document.addEventListener("pointerlockchange", () => {
  state.pointerLocked = document.pointerLockElement === canvas;
  if (!state.pointerLocked) worker.postMessage({ type: "seal" });
});
worker.addEventListener("message", ({ data: d }) => {
  if (d.type !== "looked") return;
  look.waiting = false;
  if (d.changed) restarted(d.message);
  sendLook();
});

// ---- The optics overlay (F6) and the analysis panel (F7) ----
// The desktop viewer's: the selected lens's (or system's) axis, vertices,
// F, F', H, H' and a real ray fan, stroked on a transparent canvas over
// the picture (the picture's own canvas is untouched), and the analysis
// figures (the library's SVG) below the picture, with the desktop window's
// object distance, field, defocus and rings. Both come from the worker
// (App.optics, App.analysis) after every change; toggling never restarts
// the picture.
const opticsCanvas = document.getElementById("optics");
const opticsCtx = opticsCanvas.getContext("2d");
const showOptics = document.getElementById("show-optics");
const showAnalysis = document.getElementById("show-analysis");
const analysisPanel = document.getElementById("analysis");
const analysisFigures = document.getElementById("analysis-figures");
const an = (id) => document.getElementById(`an-${id}`);
state.optics = { overlay: false, analysis: false, segments: 0, labels: [], analyses: 0 };

function drawOptics(o) {
  opticsCtx.clearRect(0, 0, opticsCanvas.width, opticsCanvas.height);
  if (!state.optics.overlay) return;
  opticsCtx.lineCap = "round";
  for (const [[x0, y0, x1, y1], colour, width] of o.segments) {
    opticsCtx.strokeStyle = colour;
    opticsCtx.lineWidth = width;
    opticsCtx.beginPath();
    opticsCtx.moveTo(x0, y0);
    opticsCtx.lineTo(x1, y1);
    opticsCtx.stroke();
  }
  opticsCtx.font = "13px sans-serif";
  for (const l of o.labels) {
    if (l.disc) {
      opticsCtx.fillStyle = l.colour;
      opticsCtx.beginPath();
      opticsCtx.arc(l.at[0], l.at[1], 5, 0, 2 * Math.PI);
      opticsCtx.fill();
    }
    const w = opticsCtx.measureText(l.text).width;
    opticsCtx.fillStyle = "rgba(0,0,0,0.67)";
    opticsCtx.fillRect(l.spot[0] - 2, l.spot[1] - 13, w + 4, 16);
    opticsCtx.fillStyle = l.colour;
    opticsCtx.fillText(l.text, l.spot[0], l.spot[1]);
  }
  state.optics.segments = o.segments.length;
  state.optics.labels = o.labels.map((l) => l.text);
}

function opticsSettings() {
  const num = (id, d) => (Number.isFinite(Number(an(id).value)) ? Number(an(id).value) : d);
  return {
    overlay: state.optics.overlay,
    analysis: state.optics.analysis,
    object: an("infinity").checked ? NaN : num("distance", 20),
    field: num("field", 0),
    defocus: num("defocus", 0),
    rings: Math.round(num("rings", 6)),
    width: Math.max(400, Math.min(1100, document.body.clientWidth - 40)),
  };
}
const sendOptics = () => worker.postMessage({ type: "optics", settings: opticsSettings() });

function setOptics(overlay, analysis) {
  state.optics.overlay = showOptics.checked = overlay;
  state.optics.analysis = showAnalysis.checked = analysis;
  analysisPanel.hidden = !analysis;
  an("field-value").textContent = `${an("field").value}°`;
  if (!overlay) drawOptics({ segments: [], labels: [] });
  if (state.ready) sendOptics();
}
showOptics.addEventListener("change", () => setOptics(showOptics.checked, state.optics.analysis));
showAnalysis.addEventListener("change", () => setOptics(state.optics.overlay, showAnalysis.checked));
for (const id of ["infinity", "distance", "field", "defocus", "rings"]) {
  an(id).addEventListener(id === "field" ? "input" : "change", () => setOptics(state.optics.overlay, state.optics.analysis));
}
// F6 and F7 before the page's key handler (which sends keys to the worker).
window.addEventListener(
  "keydown",
  (e) => {
    if (e.code !== "F6" && e.code !== "F7") return;
    e.preventDefault();
    e.stopPropagation();
    if (e.code === "F6") setOptics(!state.optics.overlay, state.optics.analysis);
    else setOptics(state.optics.overlay, !state.optics.analysis);
  },
  true,
);
worker.addEventListener("message", ({ data: d }) => {
  if (d.type === "ready") {
    opticsCanvas.width = d.width;
    opticsCanvas.height = d.height;
    if (state.optics.overlay || state.optics.analysis) sendOptics();
  } else if (d.type === "optics") {
    drawOptics(JSON.parse(d.json));
  } else if (d.type === "analysis") {
    if (!state.optics.analysis) return;
    analysisFigures.innerHTML = d.html;
    state.optics.analyses += 1;
  }
});

// The *Presets* menu, as the desktop's: the shipped scenes (App.presets,
// sent with "ready"); picking one opens the page with ?scene= it, the
// picture's size, spp and seed kept.
const presetMenu = document.getElementById("presets");
worker.addEventListener("message", ({ data: d }) => {
  if (d.type !== "ready" || !d.presets) return;
  const current = params.get("scene") || "";
  presetMenu.replaceChildren(new Option(current ? "" : "(default scene)", ""));
  for (const [stem, name, about] of JSON.parse(d.presets)) {
    const o = new Option(name, stem, false, stem === current || name === current);
    o.title = about;
    presetMenu.add(o);
  }
});
presetMenu.addEventListener("change", () => {
  if (!presetMenu.value) return;
  const next = new URLSearchParams(location.search);
  next.set("scene", presetMenu.value);
  next.delete("retry");
  location.search = next.toString();
});
