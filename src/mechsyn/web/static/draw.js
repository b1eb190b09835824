// SVG drawing of a planar mechanism at one frame of its simulation (no state, no I/O).
const NS = "http://www.w3.org/2000/svg";
export const GROUP_COLOURS = ["#e6550d", "#3182bd", "#31a354", "#756bb1", "#de2d26", "#636363", "#fd8d3c", "#6baed6"];

export function el(tag, attrs = {}, parent = null, text = null) {
  const e = document.createElementNS(NS, tag);
  for (const [k, v] of Object.entries(attrs)) if (v !== undefined && v !== null) e.setAttribute(k, v);
  if (text !== null) e.textContent = text;
  if (parent) parent.appendChild(e);
  return e;
}

export const linkName = (l) => (typeof l === "string" ? l : l.name);

// A file colour (the mechanism's `colors`, e.g. from Pyslvs: Green, dark-blue, (255, 0, 0))
// as a CSS colour, or null for none / a name CSS does not know (e.g. tab:purple). It is set
// through the CSSOM (element.style), which the page's CSP allows, unlike style attributes.
export function fileColour(mech, key) {
  const c = ((mech.colors || {})[key] || "").trim();
  const rgb = c.match(/^\(?\s*(\d+)\s*,\s*(\d+)\s*,\s*(\d+)\s*\)?$/);
  if (rgb) return `rgb(${rgb[1]}, ${rgb[2]}, ${rgb[3]})`;
  const PYSLVS = { "brick-red": "firebrick", "dark-gray": "dimgray", "dark-yellow": "olive", "dark-pink": "mediumvioletred" };
  const name = PYSLVS[c.toLowerCase()] || c.toLowerCase().replace(/-/g, "");
  return /^[a-z]+$/.test(name) || /^#[0-9a-f]{3,8}$/.test(name) ? name : null;
}

function fillWith(e, colour) {
  if (colour) e.style.fill = colour;
  return e;
}

export function makeView(svg, view) {
  const r = svg.getBoundingClientRect();
  const W = r.width || 800, H = r.height || 600;
  return {
    W, H, ...view,
    toScreen: ([x, y]) => [W / 2 + (x - view.ox) * view.s, H / 2 - (y - view.oy) * view.s],
    toWorld: ([px, py]) => [view.ox + (px - W / 2) / view.s, view.oy - (py - H / 2) / view.s],
  };
}

// Positions of every joint and point at frame k: the simulation's where assembled, else the file's.
export function positions(mech, sim, k) {
  const joints = {}, points = {};
  const ok = !!(sim && sim.assembled[k]);
  const at = (n) => ok && sim.points[n] && sim.points[n].position[k]; // the simulation's points: every joint, every named point
  for (const j of mech.joints) joints[j.id] = at(j.id) || j.point;
  for (const [n, p] of Object.entries(mech.points || {})) points[n] = at(n) || p.at;
  return { joints, points, assembled: ok };
}

export function membership(mech) {
  const links = {};
  for (const l of mech.links) links[linkName(l)] = { joints: [], points: [] };
  for (const j of mech.joints) for (const l of j.links || []) if (links[l]) links[l].joints.push(j.id);
  for (const [n, p] of Object.entries(mech.points || {})) if (links[p.link]) links[p.link].points.push(n);
  return links;
}

function niceStep(s) {
  const raw = 60 / s, p = 10 ** Math.floor(Math.log10(raw)), m = raw / p;
  return p * (m < 2 ? 2 : m < 5 ? 5 : 10);
}
export const gridStep = (view) => niceStep(view.s) / 2;

function drawGrid(g, v) {
  const step = gridStep(v);
  const [x0, y1] = v.toWorld([0, 0]), [x1, y0] = v.toWorld([v.W, v.H]);
  for (let i = Math.floor(x0 / step); i <= Math.ceil(x1 / step); i++) {
    const [px] = v.toScreen([i * step, 0]);
    el("line", { x1: px, y1: 0, x2: px, y2: v.H, class: i % 5 ? "gridline" : "gridline major" }, g);
  }
  for (let i = Math.floor(y0 / step); i <= Math.ceil(y1 / step); i++) {
    const [, py] = v.toScreen([0, i * step]);
    el("line", { x1: 0, y1: py, x2: v.W, y2: py, class: i % 5 ? "gridline" : "gridline major" }, g);
  }
}

function hatchedGround(g, [px, py], angle = 0) {
  const t = el("g", { transform: `translate(${px.toFixed(1)} ${py.toFixed(1)}) rotate(${angle})`, class: "ground" }, g);
  el("path", { d: "M0 0 L-9 14 L9 14 Z", class: "ground-base", fill: "#fff" }, t);
  el("line", { x1: -16, y1: 14, x2: 16, y2: 14, class: "ground-base" }, t);
  for (let x = -14; x <= 14; x += 6) el("line", { x1: x, y1: 14, x2: x - 6, y2: 21, class: "hatch-line" }, t);
}

function order(pts) {
  const c = pts.reduce((a, p) => [a[0] + p[0] / pts.length, a[1] + p[1] / pts.length], [0, 0]);
  return pts.slice().sort((a, b) => Math.atan2(a[1] - c[1], a[0] - c[0]) - Math.atan2(b[1] - c[1], b[0] - c[0]));
}

// A path through the points (null: a gap); `cyclic` (a sweep over a whole turn) joins the last
// point to the first, so a closed coupler curve has no gap where the sweep starts.
export function pathD(v, pts, cyclic = false) {
  let d = "", pen = false;
  for (const p of pts) {
    if (!p) { pen = false; continue; }
    const [x, y] = v.toScreen(p);
    d += `${pen ? "L" : "M"}${x.toFixed(1)} ${y.toFixed(1)}`;
    pen = true;
  }
  if (cyclic && pen && pts[0] && pts.length > 2) { const [x, y] = v.toScreen(pts[0]); d += `L${x.toFixed(1)} ${y.toFixed(1)}`; }
  return d;
}

// Whether a simulation's sweep is a whole turn of an R input (its last row, one step on, is its first).
export function wholeTurn(sim) {
  const x = sim.input.values, n = x.length;
  return sim.input.type === "R" && n > 2 && Math.abs(Math.abs(x[n - 1] - x[0]) + Math.abs(x[1] - x[0]) - 360) < 1e-6;
}

function muClass(mu) {
  if (mu === null || mu === undefined) return null;
  const dev = Math.abs(90 - mu);
  return dev <= 50 ? "mu-ok" : dev <= 60 ? "mu-poor" : "mu-bad";
}

function sliderAxis(mech, sim, j, k) {
  let [ax, ay] = j.axis || [1, 0];
  const moving = j.links.find((l) => l !== mech.ground);
  const carrier = j.links[0] !== mech.ground ? j.links[0] : null;
  if (carrier && sim && sim.links[carrier] && sim.assembled[k]) {
    const a = sim.links[carrier].angle;
    const d = ((a[k] - a[0]) * Math.PI) / 180;
    [ax, ay] = [ax * Math.cos(d) - ay * Math.sin(d), ax * Math.sin(d) + ay * Math.cos(d)];
  }
  return { ax, ay, moving };
}

// The elements an error or warning names: {element: {kind, id}} or {elements: [...]} → ["kind:id"].
function elementKeys(e) {
  return (e.elements || (e.element ? [e.element] : [])).map((x) => `${x.kind}:${x.id}`);
}

// A label writer that moves a label down until it overlaps none placed before (coincident
// joints, e.g. a slider's R and P joints or Jansen's P1 and P1_2, get labels one under the other).
function placeLabels() {
  const placed = [];
  return (layer, x, y, text) => {
    const w = 7 * String(text).length + 4, hgt = 15;
    let yy = y;
    for (let guard = 0; guard < 12 && placed.some((b) => x < b.x + b.w && b.x < x + w && yy - hgt < b.y && b.y - hgt < yy); guard++) yy += hgt;
    placed.push({ x, y: yy, w });
    return el("text", { x, y: yy, class: "label" }, layer, text);
  };
}

// Draw everything into svg; returns {joints, paths} element maps (the contract: data-joint, data-path).
export function draw(svg, state) {
  const { mech, sim, frame: k, view, opts } = state;
  const v = makeView(svg, view);
  svg.replaceChildren();
  svg.setAttribute("viewBox", `0 0 ${v.W} ${v.H}`);
  const layers = {};
  for (const name of ["grid", "paths", "ground", "links", "sliders", "joints", "points", "marks", "labels"])
    layers[name] = el("g", { class: `layer-${name}` }, svg);
  if (opts.grid) drawGrid(layers.grid, v);
  if (!mech) return { joints: {}, paths: {} };
  const pos = positions(mech, state.poseFromFile ? null : sim, k);
  const P = (p) => v.toScreen(p);
  const invalid = new Set((state.errors || []).concat(state.diagnostics || []).flatMap(elementKeys));
  const sel = state.selected ? `${state.selected.kind}:${state.selected.id}` : null;
  const labels = placeLabels();
  const groupOf = (opts.assurColours && state.analysis && state.analysis.groupOf) || {};
  const muAt = {};
  if (sim && sim.derived.transmission_angle)
    for (const [key, t] of Object.entries(sim.derived.transmission_angle)) muAt[key.split("-")[1]] = t.values[k];
  // paths of the named points (full sweep)
  const paths = {};
  const named = sim ? Object.keys(mech.points || {}).filter((n) => sim.points[n]) : [];
  for (const n of named)
    paths[n] = el("path", { d: pathD(v, sim.points[n].position, wholeTurn(sim)), class: "path", "data-path": n }, layers.paths);
  // ground symbols
  for (const j of mech.joints) {
    if (!(j.links || []).includes(mech.ground) || !pos.joints[j.id]) continue;
    if (j.type === "P") {
      const { ax, ay } = sliderAxis(mech, sim, j, k);
      const [px, py] = P(pos.joints[j.id]);
      const L = 60;
      el("line", { x1: px - ax * L, y1: py + ay * L, x2: px + ax * L, y2: py - ay * L, class: "guide" }, layers.ground);
    } else hatchedGround(layers.ground, P(pos.joints[j.id]));
  }
  // links: bars and plates
  const mem = membership(mech);
  for (const [name, m] of Object.entries(mem)) {
    if (name === mech.ground) continue;
    const pts = m.joints.map((id) => pos.joints[id]).concat(m.points.map((n) => pos.points[n])).filter(Boolean).map(P);
    if (pts.length < 2) continue;
    let cls = "";
    const colour = groupOf[name] !== undefined ? GROUP_COLOURS[groupOf[name] % GROUP_COLOURS.length] : null;
    if (!colour) for (const id of m.joints) if (muAt[id] !== undefined && muClass(muAt[id])) cls = " " + muClass(muAt[id]);
    if (invalid.has(`link:${name}`)) cls += " invalid";
    const g = el("g", { "data-link": name, "data-group": groupOf[name] }, layers.links);
    if (sel === `link:${name}`) g.setAttribute("data-selected", "true");
    // a group colour is set through the CSSOM: a presentation attribute loses to the class rules
    const paint = (e, fill) => { if (colour && !cls.includes("invalid")) { e.style.stroke = colour; if (fill) e.style.fill = colour; } return e; };
    if (pts.length === 2) {
      paint(el("line", { x1: pts[0][0], y1: pts[0][1], x2: pts[1][0], y2: pts[1][1], class: "link-bar" + cls }, g));
      el("line", { x1: pts[0][0], y1: pts[0][1], x2: pts[1][0], y2: pts[1][1], class: "link-hit" }, g);
    } else {
      const poly = order(pts).map((p) => p.map((c) => c.toFixed(1)).join(",")).join(" ");
      paint(el("polygon", { points: poly, class: "link-plate" + cls }, g), true);
    }
  }
  // joints
  const joints = {};
  for (const j of mech.joints) {
    const p = pos.joints[j.id];
    if (!p) continue;
    const [px, py] = P(p);
    const onGround = (j.links || []).includes(mech.ground);
    let cls = "joint" + (onGround ? " ground" : "") + (j.actuated ? " drive" : "") + (invalid.has(`joint:${j.id}`) ? " invalid" : "");
    if (j.type === "P") {
      const { ax, ay } = sliderAxis(mech, sim, j, k);
      const ang = (Math.atan2(-ay, ax) * 180) / Math.PI;
      joints[j.id] = el("rect", { x: -14, y: -8, width: 28, height: 16, rx: 2,
        class: "slider-block" + (j.actuated ? " drive" : "") + (invalid.has(`joint:${j.id}`) ? " invalid" : ""),
        transform: `translate(${px.toFixed(1)} ${py.toFixed(1)}) rotate(${ang.toFixed(1)})`, "data-joint": j.id,
        "data-x": p[0], "data-y": p[1] }, layers.sliders);
      const L = onGround ? 60 : 40;
      if (!onGround) el("line", { x1: px - ax * L, y1: py + ay * L, x2: px + ax * L, y2: py - ay * L, class: "guide" }, layers.ground);
      // the handle that turns the guide (dragged in Select)
      el("circle", { cx: (px + ax * L).toFixed(1), cy: (py - ay * L).toFixed(1), r: 5, class: "guide-handle", "data-handle": j.id }, layers.marks);
    } else {
      joints[j.id] = fillWith(el("circle", { cx: px.toFixed(1), cy: py.toFixed(1), r: 6.5, class: cls, "data-joint": j.id,
        "data-x": p[0], "data-y": p[1] }, layers.joints), fileColour(mech, j.id));
    }
    if (sel === `joint:${j.id}`) joints[j.id].setAttribute("data-selected", "true");
    labels(layers.labels, px + 9, py - 9, j.id);
  }
  for (const [n, p] of Object.entries(pos.points)) {
    if (!p) continue;
    const [px, py] = P(p);
    const c = fillWith(el("circle", { cx: px.toFixed(1), cy: py.toFixed(1), r: 5, class: "point", "data-point": n },
      layers.points), fileColour(mech, n));
    if (sel === `point:${n}`) c.setAttribute("data-selected", "true");
    labels(layers.labels, px + 8, py + 14, n);
  }
  // dead points: × on every path where a working range ends
  if (sim) for (const ev of sim.events) {
    if (ev.kind !== "dead point") continue;
    for (const n of named) {
      const pts = sim.points[n].position, p = pts[ev.index] || pts[ev.index - 1];
      if (!p) continue;
      const [px, py] = P(p);
      el("path", { d: `M${px - 6} ${py - 6}L${px + 6} ${py + 6}M${px - 6} ${py + 6}L${px + 6} ${py - 6}`,
        class: "deadpoint", "data-deadpoint": ev.index }, layers.marks);
    }
  }
  // joint reactions at this frame (Forces tab): arrows from the joint, the largest a quarter of the length scale
  for (const a of state.arrows || []) {
    const [x1, y1] = P(a.at), [x2, y2] = P([a.at[0] + a.vec[0], a.at[1] + a.vec[1]]);
    const L = Math.hypot(x2 - x1, y2 - y1);
    if (L < 2) continue;
    const ux = (x2 - x1) / L, uy = (y2 - y1) / L;
    el("path", { d: `M${x1.toFixed(1)} ${y1.toFixed(1)}L${x2.toFixed(1)} ${y2.toFixed(1)}M${(x2 - 9 * ux - 4 * uy).toFixed(1)} ${(y2 - 9 * uy + 4 * ux).toFixed(1)}L${x2.toFixed(1)} ${y2.toFixed(1)}L${(x2 - 9 * ux + 4 * uy).toFixed(1)} ${(y2 - 9 * uy - 4 * ux).toFixed(1)}`,
      class: "force-arrow", "data-force": a.id }, layers.marks);
  }
  // synthesis targets and a previewed path
  (state.targets || []).forEach((t, i) => {
    const [px, py] = P(t);
    el("circle", { cx: px, cy: py, r: 7, class: "target", "data-target": i }, layers.marks);
    if (state.showPoses) { // a pose of the guided body: its angle as a tick
      const a = (((state.targetAngles || [])[i] || 0) * Math.PI) / 180;
      el("line", { x1: px, y1: py, x2: px + 26 * Math.cos(a), y2: py - 26 * Math.sin(a), class: "pose-tick", "data-pose": i }, layers.marks);
    }
    if (state.targets.length <= 12) labels(layers.labels, px + 9, py + 4, `T${i + 1}`); // many: no labels
  });
  if (state.preview) el("path", { d: pathD(v, state.preview), class: "synth-path" }, layers.marks);
  // what other modules draw (burmester.js, robot.js, centres.js): f(layer, view, pos)
  for (const f of Object.values(state.overlays || {})) f(layers.marks, v, pos, labels);
  // the link being built
  if (state.building && state.building.length) {
    const pts = state.building.map((b) => P(b.point));
    el("polyline", { points: pts.map((p) => p.join(",")).join(" "), class: "pending" }, layers.marks);
    for (const p of pts) el("circle", { cx: p[0], cy: p[1], r: 9, class: "pending" }, layers.marks);
  }
  // errors next to their element
  for (const e of (state.errors || []).concat(state.diagnostics || [])) {
    const at = e.element || (e.elements || [])[0];
    if (!at) continue;
    let p = null;
    if (at.kind === "joint") p = pos.joints[at.id];
    if (at.kind === "point") p = pos.points[at.id];
    if (at.kind === "link" && mem[at.id]) p = pos.joints[mem[at.id].joints[0]];
    if (!p) continue;
    const [px, py] = P(p);
    const text = e.short || e.message.split(":")[0], right = px + 10 + 7.5 * text.length > v.W; // kept inside the canvas
    el("text", { x: right ? px - 10 : px + 10, y: py + 26, class: "label err", "text-anchor": right ? "end" : "start", "data-error": at.id },
      layers.labels, text);
  }
  return { joints, paths };
}

// The y-range of a plot: the full range, unless spikes (near dead points, where velocities and
// accelerations grow without bound) would flatten the rest: then the 2nd to 98th percentile
// widened by 15 %, and `clipped` says so.
export function robustRange(vals) {
  const v = vals.slice().sort((a, b) => a - b), n = v.length, q = (f) => v[Math.min(n - 1, Math.max(0, Math.round(f * (n - 1))))];
  let lo = v[0], hi = v[n - 1];
  const core = q(0.98) - q(0.02);
  const clipped = n >= 20 && core > 0 && hi - lo > 4 * core;
  if (clipped) { lo = Math.max(lo, q(0.02) - 0.15 * core); hi = Math.min(hi, q(0.98) + 0.15 * core); }
  if (hi - lo < 1e-12 * Math.max(1, Math.abs(hi))) { lo -= 1; hi += 1; }
  return { lo, hi, clipped, min: v[0], max: v[n - 1] };
}
