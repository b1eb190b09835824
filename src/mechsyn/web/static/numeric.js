// Numeric editing: the Element tab's inputs for the selected joint or point (name="x", "y" and,
// for a P joint, "angle" in degrees) and the Joints tab's table of every joint and link. Each
// change is one edit: `edit(fn)` applies fn to a copy of the mechanism, re-simulates, one undo step.
import { linkName, membership } from "./draw.js";

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

// The joints moved with joint `id` (those drawn on the same place, e.g. a slider's R and P joints).
function together(m, id) {
  const p = m.joints.find((j) => j.id === id).point;
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
    out.push({ name, a: a.id, b: b.id, length: Math.hypot(b.point[0] - a.point[0], b.point[1] - a.point[1]) });
  }
  return out;
}
export function setLength(m, name, L) {
  const row = twoJointLinks(m).find((r) => r.name === name);
  const a = m.joints.find((j) => j.id === row.a).point, b = m.joints.find((j) => j.id === row.b).point;
  const d = row.length || 1, ux = row.length ? (b[0] - a[0]) / d : 1, uy = row.length ? (b[1] - a[1]) / d : 0;
  const to = [a[0] + ux * L, a[1] + uy * L].map((c) => +c.toPrecision(12));
  moveJoint(m, row.b, 0, to[0]); moveJoint(m, row.b, 1, to[1]);
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

export function pointFields(name, p, edit) {
  return ["x", "y"].map((axis, k) => {
    const r = h("p");
    r.append(h("label", axis + " "), numberInput(p.at[k], (v) => edit((m) => { m.points[name].at[k] = v; }), { name: axis }));
    return r;
  });
}

// The Joints tab: every joint (id, x, y, type, links, drive, slide angle) and every bar's length.
export function jointTable(m, selected, edit, select) {
  const t = h("table", null, { className: "numtable" });
  t.dataset.table = "joints";
  const head = h("tr");
  for (const c of ["joint", "x", "y", "type", "links", "drive", "angle °"]) head.append(h("th", c));
  t.append(head);
  for (const j of m.joints) {
    const tr = h("tr", null, { className: selected === j.id ? "selected" : "" });
    tr.dataset.row = j.id;
    const id = h("td", j.id); id.onclick = () => select(j.id); id.style.cursor = "pointer";
    const type = h("select"); for (const ty of ["R", "P"]) type.append(h("option", ty, { value: ty, selected: j.type === ty }));
    type.onchange = () => edit((n) => setType(n.joints.find((q) => q.id === j.id), type.value));
    const links = h("input", null, { value: j.links.join(", "), className: "links" });
    links.onchange = () => edit((n) => setLinks(n, j.id, links.value));
    const drive = h("input", null, { type: "checkbox", checked: !!j.actuated });
    drive.onchange = () => edit((n) => { const q = n.joints.find((x) => x.id === j.id); if (drive.checked) q.actuated = true; else delete q.actuated; });
    const cells = [id, numberInput(j.point[0], (v) => edit((n) => moveJoint(n, j.id, 0, v))),
      numberInput(j.point[1], (v) => edit((n) => moveJoint(n, j.id, 1, v))), type, links, drive,
      j.type === "P" ? numberInput(axisAngle(j), (v) => edit((n) => { n.joints.find((q) => q.id === j.id).axis = axisOf(v); })) : h("span", "")];
    cells.forEach((c, k) => { if (k && c.dataset) c.dataset.field = ["", "x", "y", "type", "links", "drive", "angle"][k]; });
    for (const c of cells) { const td = c.tagName === "TD" ? c : h("td"); if (td !== c) td.append(c); tr.append(td); }
    t.append(tr);
  }
  const lt = h("table", null, { className: "numtable" });
  lt.dataset.table = "links";
  const lh = h("tr"); for (const c of ["link", "joints", "length"]) lh.append(h("th", c)); lt.append(lh);
  for (const r of twoJointLinks(m)) {
    const tr = h("tr"); tr.dataset.row = r.name;
    const inp = numberInput(r.length, (v) => { if (v > 0) edit((n) => setLength(n, r.name, v)); });
    inp.dataset.field = "length";
    const td = h("td"); td.append(inp);
    tr.append(h("td", r.name), h("td", `${r.a}–${r.b}`), td);
    lt.append(tr);
  }
  return [h("h3", "Joints"), t, h("h3", "Bar lengths (the second joint moves along the bar)"), lt];
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
