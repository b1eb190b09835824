// Numeric editing: the Element tab's inputs for the selected joint or point (name="x", "y" and,
// for a P joint, "angle" in degrees) and the Joints tab's table of every joint and link. Each
// change is one edit: `edit(fn)` applies fn to a copy of the mechanism, re-simulates, one undo step.
import { linkName, membership } from "./draw.js";

// Bidirectional controls and zero-width characters written visibly (<U+202E>): a name from a
// file or a request shows what it holds, never text reordered or hidden by them (the same set
// as mechsyn.io.files.HIDDEN_CHARS; "Trojan Source", CVE-2021-42574).
const HIDDEN = /[\u061c\u200b-\u200f\u202a-\u202e\u2060-\u2064\u2066-\u2069\ufeff]/g;
export const visible = (s) => String(s ?? "").replace(HIDDEN, (c) => `<U+${c.charCodeAt(0).toString(16).toUpperCase().padStart(4, "0")}>`);

export function h(tag, text, attrs = {}) {
  const e = document.createElement(tag);
  if (text !== undefined && text !== null) e.textContent = text;
  Object.assign(e, attrs);
  return e;
}

const fmt = (v) => String(+(+v).toPrecision(8));
export const axisAngle = (j) => { const [ax, ay] = j.axis || [1, 0]; return +((Math.atan2(ay, ax) * 180) / Math.PI).toFixed(4); };
export const axisOf = (deg) => [Math.cos((deg * Math.PI) / 180), Math.sin((deg * Math.PI) / 180)].map((c) => +c.toFixed(12));

// A number input that calls onValue(number) when a finite value is entered (Enter or leaving it).
function numberInput(value, onValue, attrs = {}) {
  const i = h("input", null, { type: "text", inputMode: "decimal", value: fmt(value), ...attrs });
  i.onchange = () => {
    const v = Number(i.value.trim().replace(",", "."));
    if (i.value.trim() === "" || !Number.isFinite(v)) { i.setCustomValidity("a number"); i.reportValidity(); return; }
    onValue(v);
  };
  return i;
}

// The joints moved with joint `id`: on a planar drawing those drawn on the same place (a slider's R
// and P joints); in a spatial file the joint alone (the joints of a spherical linkage may all be
// written at its centre, and moving them together would move their axes off it).
function together(m, id) {
  const p = m.joints.find((j) => j.id === id).point;
  if (m.kind !== "planar") return m.joints.filter((j) => j.id === id);
  return m.joints.filter((j) => j.point[0] === p[0] && j.point[1] === p[1]);
}

export function moveJoint(m, id, axis, v) { for (const j of together(m, id)) j.point[axis] = v; }

// Length of a bar (a link with two R joints); setting it moves the second joint along the line from the first.
export function twoJointLinks(m) {
  const out = [];
  for (const [name, g] of Object.entries(membership(m))) {
    if (name === m.ground || g.joints.length !== 2) continue;
    const [a, b] = g.joints.map((id) => m.joints.find((j) => j.id === id));
    if (a.type !== "R" || b.type !== "R") continue; // a slider block: its joints' distance is no length
    out.push({ name, a: a.id, b: b.id, length: Math.hypot(...b.point.map((c, i) => c - a.point[i])) }); // 2-D or 3-D
  }
  return out;
}
export function setLength(m, name, L) {
  const row = twoJointLinks(m).find((r) => r.name === name);
  const a = m.joints.find((j) => j.id === row.a).point, b = m.joints.find((j) => j.id === row.b).point;
  const u = row.length ? b.map((c, i) => (c - a[i]) / row.length) : a.map((_, i) => +(i === 0));
  a.map((c, i) => +(c + u[i] * L).toPrecision(12)).forEach((c, i) => moveJoint(m, row.b, i, c));
}

// The Element tab's fields of joint j: x, y (and the slide angle of a P joint).
export function jointFields(j, edit) {
  const out = [];
  const row = (label, input) => { const p = h("p"); p.append(h("label", label + " "), input); return p; };
  out.push(row("x", numberInput(j.point[0], (v) => edit((m) => moveJoint(m, j.id, 0, v)), { name: "x" })));
  out.push(row("y", numberInput(j.point[1], (v) => edit((m) => moveJoint(m, j.id, 1, v)), { name: "y" })));
  if (j.type === "P")
    out.push(row("slide angle (°)", numberInput(axisAngle(j), (v) => edit((m) => { m.joints.find((q) => q.id === j.id).axis = axisOf(v); }), { name: "angle" })));
  return out;
}

// The pair types of spatial files, in words (the Element tab's heading).
export const PAIR_NAMES = { R: "revolute", P: "prismatic", C: "cylindrical", H: "helical", U: "universal, Hooke",
  S: "spherical, ball", S_pin: "spherical with a pin" };

// A spatial file's coordinates as shown: rounding noise under 1e-12 of its length scale (the diagonal
// of its joints' box), e.g. 3.3e-16 left by a closure computation, shown as 0 (the file keeps it).
function shownCoords(m) {
  const pts = m.joints.map((j) => j.point).filter(Boolean);
  const L = Math.hypot(...[0, 1, 2].map((i) => Math.max(...pts.map((p) => p[i] || 0)) - Math.min(...pts.map((p) => p[i] || 0)))) || 1;
  return (v) => (Math.abs(v) < 1e-12 * L ? 0 : v);
}

// A direction typed as three numbers; refused (left as it was) when it is zero.
function axisInputs(v, names, onAxis) {
  return v.map((c, k) => numberInput(Math.abs(c) < 1e-12 ? 0 : c, (x) => {
    const a = v.slice(); a[k] = x;
    if (a.every((q) => q === 0)) return;
    onAxis(a);
  }, { name: names[k] }));
}

// The Element tab's fields of a spatial joint j: its point (x, y, z, at the drawn pose) and its
// axis (and a U joint's second axis: the arm on its second link) as numbers.
export function spatialJointFields(m, j, edit) {
  const shown = shownCoords(m);
  const row = (label, ...inputs) => { const p = h("p", null, { className: "xyz" }); p.append(h("label", label), ...inputs); return p; };
  const out = [row("point (x, y, z) at the drawn pose", ...["x", "y", "z"].map((name, k) =>
    numberInput(shown(j.point[k]), (v) => edit((n) => moveJoint(n, j.id, k, v)), { name })))];
  const setAxis = (key) => (a) => edit((n) => { n.joints.find((q) => q.id === j.id)[key] = a; });
  if (j.axis) out.push(row(j.type === "U" ? `axis on ${j.links[0]} (direction)` : "axis (direction; its length does not matter)", ...axisInputs(j.axis, ["ax", "ay", "az"], setAxis("axis"))));
  if (j.axis2) out.push(row(`axis on ${j.links[1]} (direction)`, ...axisInputs(j.axis2, ["bx", "by", "bz"], setAxis("axis2"))));
  return out;
}

export function pointFields(name, p, edit) {
  return ["x", "y", "z"].slice(0, p.at.length).map((axis, k) => {
    const r = h("p");
    r.append(h("label", axis + " "), numberInput(p.at[k], (v) => edit((m) => { m.points[name].at[k] = v; }), { name: axis }));
    return r;
  });
}

// The Joints tab: every joint (id, x, y, type, links, drive, slide angle) and every bar's length.
export function jointTable(m, selected, edit, select, onLength = null) {
  if (m.kind !== "planar") return spatialJointTable(m, selected, edit, select);
  const t = jointsHead(["joint", "x", "y", "type", "links", "drive", "angle °"]);
  for (const j of m.joints) {
    const [tr, id] = jointRow(j, selected, select);
    const type = h("select"); for (const ty of ["R", "P"]) type.append(h("option", ty, { value: ty, selected: j.type === ty }));
    type.onchange = () => edit((n) => setType(n.joints.find((q) => q.id === j.id), type.value));
    const links = h("input", null, { value: j.links.join(", "), className: "links" });
    links.onchange = () => edit((n) => setLinks(n, j.id, links.value));
    const cells = [id, numberInput(j.point[0], (v) => edit((n) => moveJoint(n, j.id, 0, v))),
      numberInput(j.point[1], (v) => edit((n) => moveJoint(n, j.id, 1, v))), type, links, driveBox(j, edit),
      j.type === "P" ? numberInput(axisAngle(j), (v) => edit((n) => { n.joints.find((q) => q.id === j.id).axis = axisOf(v); })) : h("span", "")];
    t.append(withCells(tr, cells, ["", "x", "y", "type", "links", "drive", "angle"]));
  }
  return [h("h3", "Joints"), t, h("h3", onLength ? "Bar lengths (re-assembled on the drawn branch, the other lengths kept)" : "Bar lengths (the second joint moves along the bar)"), barTable(m, edit, onLength)];
}

// The joint table's head row, a joint's row (its name selects it), its drive box, its cells.
function jointsHead(columns) {
  const t = h("table", null, { className: "numtable" }), head = h("tr");
  t.dataset.table = "joints";
  for (const c of columns) head.append(h("th", c));
  t.append(head);
  return t;
}
function jointRow(j, selected, select) {
  const tr = h("tr", null, { className: selected === j.id ? "selected" : "" });
  tr.dataset.row = j.id;
  const id = h("td", j.id); id.onclick = () => select(j.id); id.style.cursor = "pointer";
  return [tr, id];
}
function driveBox(j, edit) {
  const drive = h("input", null, { type: "checkbox", checked: !!j.actuated });
  drive.onchange = () => edit((n) => { const q = n.joints.find((x) => x.id === j.id); if (drive.checked) q.actuated = true; else delete q.actuated; });
  return drive;
}
function withCells(tr, cells, fields) {
  cells.forEach((c, k) => { if (k && c.dataset) c.dataset.field = fields[k]; });
  for (const c of cells) { const td = c.tagName === "TD" ? c : h("td"); if (td !== c) td.append(c); tr.append(td); }
  return tr;
}

function barTable(m, edit, onLength = null) {
  const lt = h("table", null, { className: "numtable" });
  lt.dataset.table = "links";
  const lh = h("tr"); for (const c of ["link", "joints", "length"]) lh.append(h("th", c)); lt.append(lh);
  for (const r of twoJointLinks(m)) {
    const tr = h("tr"); tr.dataset.row = r.name;
    const inp = numberInput(r.length, (v) => { if (!(v > 0)) return; if (onLength) onLength(r.name, v); else edit((n) => setLength(n, r.name, v)); });
    inp.dataset.field = "length";
    const td = h("td"); td.append(inp);
    tr.append(h("td", r.name), h("td", `${r.a}–${r.b}`), td);
    lt.append(tr);
  }
  return lt;
}

// The Joints tab of a spatial file: every joint's point (x, y, z at the drawn pose), type, links
// and drive (its axes in the Element tab: the side panel has no room for six more numbers); every
// bar's length in 3-D.
function spatialJointTable(m, selected, edit, select) {
  const shown = shownCoords(m), t = jointsHead(["joint", "x", "y", "z", "type", "links", "drive"]);
  for (const j of m.joints) {
    const [tr, id] = jointRow(j, selected, select);
    const coords = (j.point || []).map((c, k) => numberInput(shown(c), (v) => edit((n) => moveJoint(n, j.id, k, v)), { size: 6 }));
    t.append(withCells(tr, [id, ...coords, h("span", j.type), h("span", j.links.join(", ")), driveBox(j, edit)],
      ["", "x", "y", "z", "type", "links", "drive"]));
  }
  const bars = twoJointLinks(m).length ? [h("h3", "Bar lengths in 3-D (the second joint moves along the bar)"), barTable(m, edit)] : [];
  return [h("h3", "Joints at the drawn pose (click a joint for its axes in the Element tab)"), t, ...bars];
}

// A joint made a P joint slides along x until its angle is typed or its guide's handle turned.
export function setType(j, type) {
  j.type = type;
  if (type === "R") delete j.axis;
  else if (!j.axis) j.axis = [1, 0];
}

export function setLinks(m, id, text) {
  const j = m.joints.find((q) => q.id === id);
  j.links = text.split(",").map((s) => s.trim()).filter(Boolean);
  for (const l of j.links) if (!m.links.map(linkName).includes(l)) m.links.push(l);
}
