// Property-panel fields bound to JSON paths of the scene ("objects[2].temperature_k"), the
// paths the validator's errors name: an error is shown at the field whose path it names.

export function parsePath(path) {
  const keys = [];
  String(path).replace(/^\$\.?/, "").replace(/^\//, "")
    .replace(/\[(\d+)\]|\/(\d+)(?=\/|$)|([^.[\]/]+)/g, (_, i1, i2, k) => {
      keys.push(i1 !== undefined ? Number(i1) : i2 !== undefined ? Number(i2) : k);
      return "";
    });
  return keys;
}
export function formatPath(keys) {
  return keys.map((k, i) => (typeof k === "number" ? `[${k}]` : i ? `.${k}` : k)).join("");
}
// "objects[2].temperature_k", "$.objects[2]...", "/objects/2/..." all read the same
export const normalisePath = (path) => formatPath(parsePath(path));

export function getAt(doc, path) {
  return parsePath(path).reduce((v, k) => (v == null ? undefined : v[k]), doc);
}
export function setAt(doc, path, value) {
  const keys = parsePath(path);
  let v = doc;
  keys.slice(0, -1).forEach((k, i) => {
    if (v[k] == null) v[k] = typeof keys[i + 1] === "number" ? [] : {};
    v = v[k];
  });
  const last = keys[keys.length - 1];
  if (value === undefined) delete v[last];
  else v[last] = value;
}

// Text typed into a field back to JSON: numbers stay numbers, lists of numbers lists, and
// anything else stays the text typed, so that the validator names what is wrong with it.
export function parseValue(text, kind) {
  const t = text.trim();
  if (kind === "number") return t !== "" && Number.isFinite(Number(t)) ? Number(t) : t;
  if (kind === "vector") {
    const parts = t.split(/[\s,]+/).filter(Boolean);
    if (parts.length === 1 && Number.isFinite(Number(parts[0]))) return Number(parts[0]);
    return parts.map((p) => (Number.isFinite(Number(p)) ? Number(p) : p));
  }
  return text;
}

const kindOf = (v) =>
  typeof v === "number" ? "number" : typeof v === "boolean" ? "boolean"
    : Array.isArray(v) && v.every((x) => typeof x === "number") ? "vector" : "text";

// One labelled field; spec: {label, path, kind?, options?, unit?, placeholder?}
export function field(doc, spec, onChange) {
  const value = getAt(doc, spec.path);
  const kind = spec.kind || kindOf(value);
  const row = document.createElement("div");
  row.className = "field";
  row.dataset.path = normalisePath(spec.path);
  const label = document.createElement("label");
  label.textContent = spec.unit ? `${spec.label} (${spec.unit})` : spec.label;
  let input;
  if (spec.options) {
    input = document.createElement("select");
    const opts = [...new Set([...(value !== undefined ? [String(value)] : []), ...spec.options])];
    for (const o of opts) input.add(new Option(o, o, false, o === String(value)));
  } else if (kind === "boolean") {
    input = document.createElement("input");
    input.type = "checkbox";
    input.checked = Boolean(value);
  } else {
    input = document.createElement("input");
    input.value = value === undefined ? "" : Array.isArray(value) ? value.join(", ") : String(value);
    if (spec.placeholder) input.placeholder = spec.placeholder;
  }
  input.name = row.dataset.path;
  label.htmlFor = input.id = `f-${row.dataset.path.replace(/[^\w-]/g, "_")}`;
  const commit = () => {
    let v;
    if (kind === "boolean") v = input.checked;
    else if (input.value.trim() === "" && !spec.options) v = undefined;
    else v = parseValue(input.value, kind);
    setAt(doc, spec.path, v);
    onChange(spec.path);
  };
  input.addEventListener(input.tagName === "SELECT" || kind === "boolean" ? "change" : "input", commit);
  row.append(label, input);
  return row;
}

// Marks the fields the errors name; returns the errors no field shows.
export function showFieldErrors(container, errors) {
  for (const f of container.querySelectorAll(".field")) {
    f.classList.remove("error");
    f.querySelector(".err")?.remove();
  }
  const rest = [];
  for (const e of errors) {
    const p = normalisePath(e.json_path || "");
    let best = null;
    for (const f of container.querySelectorAll(".field")) {
      const fp = f.dataset.path;
      if (p === fp || p.startsWith(`${fp}.`) || p.startsWith(`${fp}[`)) {
        if (!best || fp.length > best.dataset.path.length) best = f;
      }
    }
    if (!best) {
      rest.push(e);
      continue;
    }
    best.classList.add("error");
    const msg = document.createElement("div");
    msg.className = "err";
    msg.textContent = e.message;
    best.appendChild(msg);
  }
  return rest;
}
