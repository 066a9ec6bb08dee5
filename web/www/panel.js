// lensview's editing panel: DOM rows for the rows the library describes
// (App.panel's JSON: the items, the selected one's fields, the labels of
// Undo and Redo). It parses nothing and checks nothing: a value goes to the
// worker as typed (App.set), which makes the desktop panel's Document edit
// and answers with a new panel, or with the library's one-line error.
// send(message) posts to the render worker (main.js). Buttons (the Add
// menu, Delete, Duplicate, …) go as actions (App.act), which answer with
// the item to select.

export function createPanel(root, send) {
  const items = root.querySelector("#items");
  const fields = root.querySelector("#fields");
  const undo = root.querySelector("#undo");
  const redo = root.querySelector("#redo");
  items.addEventListener("change", () => send({ type: "select", id: items.value }));
  undo.addEventListener("click", () => send({ type: "undo" }));
  redo.addEventListener("click", () => send({ type: "redo" }));

  // The Add menu and the selected item's buttons, made here (before the
  // fields) so the page's HTML needs nothing for them.
  const add = document.createElement("select");
  add.id = "add";
  const actions = document.createElement("div");
  actions.id = "actions";
  const addRow = document.createElement("div");
  addRow.append("Add: ", add);
  fields.before(addRow, actions);
  add.addEventListener("change", () => {
    if (add.value) send({ type: "act", id: items.value, action: add.value });
    add.value = "";
  });

  // One input for a field: text for numbers and vectors (sent on Enter or
  // leaving it), a list for a choice, plain text for a readout.
  function input(item, f) {
    if (f.kind === "readout") {
      const span = document.createElement("span");
      span.textContent = f.value;
      return span;
    }
    let el;
    if (f.kind === "choice") {
      el = document.createElement("select");
      for (const [value, label] of f.options) el.add(new Option(label, value));
    } else if (f.kind === "lines") {
      // A prescription's table: sent on leaving it.
      el = document.createElement("textarea");
      el.rows = 6;
      el.cols = 36;
    } else {
      el = document.createElement("input");
      el.type = "text";
      el.size = f.kind === "vec3" || f.kind === "text" ? 24 : 10;
    }
    el.id = `field-${f.key}`;
    el.value = f.value;
    el.addEventListener("change", () => send({ type: "set", id: item, key: f.key, value: el.value }));
    return el;
  }

  // Shows a panel (parsed JSON), keeping the item list's scroll.
  return function show(p) {
    items.replaceChildren(...p.items.map(([id, label]) => new Option(label, id)));
    items.value = p.selected;
    undo.disabled = !p.undo;
    redo.disabled = !p.redo;
    undo.title = p.undo ? `undo: ${p.undo}` : "nothing to undo";
    redo.title = p.redo ? `redo: ${p.redo}` : "nothing to redo";
    add.replaceChildren(new Option("(choose what to add)", ""), ...p.adds.map(([a, label]) => new Option(label, a)));
    add.value = "";
    actions.replaceChildren(
      ...p.actions.map(([a, label]) => {
        const b = document.createElement("button");
        b.id = `action-${a}`;
        b.textContent = label;
        b.addEventListener("click", () => send({ type: "act", id: p.selected, action: a }));
        return b;
      }),
    );
    fields.replaceChildren(
      ...p.fields.map((f) => {
        const tr = document.createElement("tr");
        const th = document.createElement("th");
        th.textContent = f.label;
        const td = document.createElement("td");
        td.append(input(p.selected, f));
        tr.append(th, td);
        return tr;
      }),
    );
  };
}
