// lensview's render worker: holds the wasm App, renders in slices and posts
// each new picture (RGBA, transferred) to the page (main.js). Threads: when
// the page is cross-origin isolated, initThreadPool starts wasm-bindgen-rayon's
// pool (one worker per core) and the library's rayon loops run on it; rayon
// blocks this worker while they do, which the page's main thread may not.
// The panel: the worker posts App.panel's JSON for the selected item after
// every change, and hands the page's edits, undo and redo to the App.
// Two builds of the module (web/build.sh): pkg/ with threads (atomics, a
// shared memory, the pool) where the page is cross-origin isolated and the
// browser makes a shared memory; pkg-st/ (one thread, a plain memory)
// otherwise: Firefox, Safari and WebKitGTK refuse a shared memory on a page
// that is not isolated.
function sharedMemory() {
  try {
    return new WebAssembly.Memory({ initial: 1, maximum: 1, shared: true }).buffer instanceof SharedArrayBuffer;
  } catch {
    return false;
  }
}
const threaded = self.crossOriginIsolated === true && typeof SharedArrayBuffer === "function" && sharedMemory();
let App = null; // the module's App class, once loaded

let app = null;
let threads = 1;
let generation = 0; // pictures started; a frame says which one it shows
let started = 0; // when the picture of `generation` started
let [previewMs, samplesMs] = [0, 0]; // its time in block previews and in samples
const wake = new MessageChannel();
let awake = false;
let selected = ""; // the panel's item ("": the App picks the first lens)

function postPanel() {
  const json = app.panel(selected);
  selected = JSON.parse(json).selected;
  postMessage({ type: "panel", json });
  postOptics();
}

// Posts what a panel edit, undo or redo did; restarts the picture if it
// changed.
function edited(changed, t) {
  postMessage({ type: "edited", changed, message: app.message() });
  if (changed) changedAt(t);
  postPanel();
}

// A new picture after a change made at `t`; a camera move's picture moved
// into the new view (App.step's "reprojected" stage) is shown at once.
function changedAt(t) {
  restart();
  started = t;
  if (app.stage() === "reprojected") frame();
}

function frame() {
  const rgba = app.rgba();
  postMessage(
    {
      type: "frame",
      rgba,
      width: app.width(),
      height: app.height(),
      samplesDone: app.samplesDone(),
      spp: app.spp(),
      stage: app.stage(),
      done: app.done(),
      generation,
      renderMs: performance.now() - started,
      previewMs,
      samplesMs,
    },
    [rgba.buffer],
  );
}

// Renders for about 30 ms (at least one step), posts the picture, and comes
// back after the messages that arrived meanwhile (keys, files).
function work() {
  awake = false;
  if (!app || app.done()) return;
  const t0 = performance.now();
  for (let t = t0; ; ) {
    const more = app.step(threads);
    const now = performance.now();
    if (app.stage().endsWith("blocks")) previewMs += now - t;
    else samplesMs += now - t;
    t = now;
    if (!more || now - t0 >= 30) break;
  }
  frame();
  schedule();
}

function schedule() {
  if (!awake && app && !app.done()) {
    awake = true;
    wake.port2.postMessage(0);
  }
}
wake.port1.onmessage = work;

function restart() {
  generation += 1;
  [previewMs, samplesMs] = [0, 0];
  started = performance.now();
  schedule();
}

async function start(d) {
  try {
    postMessage({ type: "starting", step: "module" });
    const pkg = await import(threaded ? "./pkg/lensview_web.js" : "./pkg-st/lensview_web.js");
    await pkg.default();
    App = pkg.App;
    if (threaded && d.threads > 1) {
      postMessage({ type: "starting", step: "threads" });
      await pkg.initThreadPool(d.threads);
    }
    postMessage({ type: "starting", step: "scene" });
  } catch (err) {
    postMessage({ type: "error", text: `error: the page's WebAssembly did not start: ${err}` });
    return;
  }
  threads = App.threads();
  const t = performance.now();
  try {
    app = new App(d.scene, d.width, d.height, d.spp, d.seed);
  } catch (err) {
    postMessage({ type: "error", text: String(err) });
    return;
  }
  postMessage({ type: "ready", threads, width: app.width(), height: app.height(), presets: App.presets() });
  postPanel();
  restart();
  started = t;
}

onmessage = async ({ data: d }) => {
  if (d.type === "start") return start(d);
  if (!app) return;
  if (d.type === "key") {
    const t = performance.now();
    const changed = app.key(d.code);
    postMessage({ type: "key", changed, message: app.message() });
    if (changed) {
      changedAt(t);
      postPanel();
    }
  } else if (d.type === "look") {
    const t = performance.now();
    const changed = app.look(d.dx, d.dy);
    postMessage({ type: "looked", changed, message: app.message() });
    if (changed) {
      changedAt(t);
      postPanel();
    }
  } else if (d.type === "seal") {
    app.seal();
  } else if (d.type === "open") {
    try {
      app.open(d.name, d.bytes);
      postMessage({ type: "opened", name: d.name });
      restart();
      postPanel();
    } catch (err) {
      postMessage({ type: "error", text: String(err) });
    }
  } else if (d.type === "select") {
    selected = d.id;
    postPanel();
  } else if (d.type === "set") {
    const t = performance.now();
    try {
      edited(app.set(d.id, d.key, d.value), t);
    } catch (err) {
      // The library's one line; the panel shows the document's value again.
      postMessage({ type: "error", text: String(err) });
      postPanel();
    }
  } else if (d.type === "act") {
    // A panel button (Add, Delete, Duplicate, …): the document's edit, and
    // the item it selects.
    const t = performance.now();
    try {
      const r = JSON.parse(app.act(d.id, d.action));
      selected = r.selected;
      edited(r.changed, t);
    } catch (err) {
      postMessage({ type: "error", text: String(err) });
      postPanel();
    }
  } else if (d.type === "undo" || d.type === "redo") {
    const t = performance.now();
    edited(d.type === "undo" ? app.undo() : app.redo(), t);
  } else if (d.type === "toml") {
    postMessage({ type: "toml", id: d.id, text: app.sceneToml() });
  }
};

// The optics overlay (F6) and the analysis panel (F7): main.js switches
// them and sends the analysis settings; while on, the worker posts the
// selected lens's overlay (App.optics's JSON) and analysis (App.analysis's
// HTML) after every change the panel is posted for (keys, edits, undo,
// files, selection). Display only: nothing here restarts the picture.
const optics = { overlay: false, analysis: false, object: NaN, field: 0, defocus: 0, rings: 6, width: 640 };
function postOptics() {
  if (!app) return;
  if (optics.overlay) postMessage({ type: "optics", json: app.optics(selected, optics.object) });
  if (optics.analysis) {
    const o = optics;
    postMessage({ type: "analysis", html: app.analysis(selected, o.object, o.field, o.defocus, o.rings, o.width) });
  }
}
addEventListener("message", ({ data: d }) => {
  if (d.type === "optics") {
    Object.assign(optics, d.settings);
    postOptics();
  }
});
