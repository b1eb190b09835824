// mechsyn studio: the editor's state, the canvas interaction and the side panels.
import { call, coalescing, eventsUrl, transport } from "./api.js";
import { draw, gridStep, linkName, makeView, membership, positions } from "./draw.js";
import { checkKey, geometryChecks, tidy, topologyKey } from "./checks.js";
import { bindKeys } from "./keys.js";
import { mountPlayer } from "./player.js";
import { mountSynthesis } from "./synthesis.js";
import { mountAtlas } from "./atlas.js";
import { mountForces } from "./forces.js";
import { mountPlots } from "./plots.js";
import { analysisTab } from "./analysis.js";
import { fillExamples } from "./examples.js";
import { autosave, forgetWork, guardUnload, mountFiles, savedWork, startProblem } from "./files.js";
import { axisOf, h, jointFields, jointTable, pointFields, setLinks, setType, spatialJointFields, visible, PAIR_NAMES } from "./numeric.js";
import { mountView3d } from "./view3d.js"; // view3d: the 3-D view of spatial files
import { mountSpatialTabs } from "./tabs3d.js"; // the Plots and Forces tabs of spatial files
import { mountDesign } from "./design.js"; // issue 40: dimensions, Burmester choice, robots, instant centres

// Mount the studio on `root` (the page's document, or a notebook widget's element holding
// the same markup); `onChange(mechanism)` hears every edit (the notebook widget syncs it).
export function mount(root, { onChange = null } = {}) {
const $ = (id) => root.querySelector(`#${id}`);
const svg = $("canvas");
const clone = (x) => JSON.parse(JSON.stringify(x));
const EMPTY = () => ({ name: "New mechanism", kind: "planar", ground: "frame", links: ["frame"], joints: [], points: {} });

const state = {
  mech: null, sim: null, frame: 0, view: { s: 60, ox: 0, oy: 0 }, errors: [], notes: [], analysis: null,
  opts: { grid: true, snap: false, assurColours: false }, mode: "select", selected: null, building: [],
  targets: [], preview: null, undo: [], redo: [], playing: false, dir: 1, fileName: "", dragging: false,
  renders: 0, simulations: 0, latencies: [], editLatencies: [], diagnostics: [], check: null, home: 0, dirty: false, offer: null,
};
window.__studio = state; // for tests and the benchmark (read-only use)
// view3d: shown instead of the canvas for spatial files; a click on a joint selects it (Element tab)
const view3d = mountView3d({ $, state, svg, render, select: (id) => { state.selected = { kind: "joint", id }; render(); renderElement(); } });

// ------------------------------------------------------------------ rendering
function render() {
  try {
    const arrows = forcesUi.arrows(state.frame, () => positions(state.mech, state.dragging ? null : state.sim, state.frame).joints);
    if (!view3d.shown()) draw(svg, { ...state, poseFromFile: state.dragging, arrows }); // view3d
    state.renders += 1;
    renderBanner();
    renderPlayer();
    view3d.update(); // view3d: the 3-D view, its slider range and banner lines
    designUi.update(); // issue 40: drive sliders, tool point, instant centres, planar modes hidden in 3-D
    if (spatial()) spatialUi.cursor(); else renderPlots();
    forcesUi.cursor(state.frame);
  } catch (e) {
    console.error(e);
    $("banner").replaceChildren(div("err", `drawing failed: ${e.message || e}`));
  }
}

const spatial = () => !!(state.mech && state.mech.kind !== "planar");

function div(cls, text) { const d = document.createElement("div"); d.className = cls; d.textContent = text; return d; }

// The banner: the current errors first (each outlines the element it names), then warnings, notes.
function renderBanner() {
  const items = state.errors.map((e) => div("err", e.message + (e.hint ? ` — fix: ${e.hint}` : "")));
  if (state.fatal) items.unshift(div("err", state.fatal)); // files.js: the studio cannot talk to its server
  if (state.offer) {
    const o = div("note", `unsaved work from ${state.offer.saved.replace("T", " ").slice(0, 16)} UTC (${visible(state.offer.mechanism.name)}) `);
    const yes = h("button", "Restore"), no = h("button", "Dismiss");
    yes.dataset.restore = ""; no.dataset.dismiss = "";
    yes.onclick = () => { const w = state.offer; state.offer = null; state.fileName = w.name || ""; setMech(w.mechanism, { fit: true }); };
    no.onclick = () => { state.offer = null; forgetWork(); render(); };
    o.append(yes, no);
    items.unshift(o);
  }
  for (const d of state.diagnostics) items.push(div(d.level === "error" ? "err" : d.level === "warning" ? "warn" : "note", d.message));
  const sim = state.sim;
  if (sim && !sim.assembled[state.home] && state.simFor === state.mech)
    items.push(div("err", "not assembled at the drawn pose: the links cannot meet where they are drawn. Drag a joint until they do, or type its x and y in the Element tab"));
  else if (sim && !sim.assembled[state.frame]) items.push(div("note", "not assembled at this input: outside the working range"));
  for (const n of state.notes.concat(designUi.notes())) items.push(div("note", n));
  const b = $("banner");
  b.replaceChildren(...items);
  b.dataset.level = items.length ? items[0].className : "";
}

function renderPlayer() {
  const s = $("input-slider"), sim = state.sim;
  s.max = sim ? sim.input.values.length - 1 : 0;
  s.value = state.frame;
  let text = "";
  if (sim) {
    const u = sim.input.values[state.frame];
    text = `${sim.input.joint} = ${u.toFixed(1)}${sim.input.unit === "deg" ? "°" : ""}`;
    for (const [key, t] of Object.entries(sim.derived.transmission_angle || {})) {
      const mu = t.values[state.frame];
      if (mu !== null) text += `  μ(${key}) = ${mu.toFixed(1)}°`;
    }
  }
  $("input-value").textContent = text;
  $("status").textContent = statusLine();
}

function statusLine() {
  const m = state.mech;
  if (!m) return "";
  const moving = m.links.length - 1;
  return `${visible(m.name)}: ${moving} moving links, ${m.joints.length} joints` + (state.sim ? `, ${state.sim.method}` : "");
}

// ------------------------------------------------------------------ simulation and analysis
// The sweep of an R drive starts at the drawn pose (index 0, a full turn of 180 steps); a P drive
// is swept by ± half the length scale around it, in 181 steps so the middle one (90) is the drawn pose.
const firstDrive = (m) => m.joints.find((j) => j.actuated);
const stepsFor = (m) => (firstDrive(m) && firstDrive(m).type === "P" ? 181 : 180);
const homeOf = (sim) => (sim.input.type === "P" ? (sim.assembled.length - 1) / 2 : 0);
// The assembled frame nearest to k (the slider and the plots never show an unassembled input).
function assembledNear(k) {
  const ok = state.sim ? state.sim.assembled : [];
  for (let d = 0; d < ok.length; d++) { if (ok[k - d]) return k - d; if (ok[k + d]) return k + d; }
  return k;
}
const simulateSoon = coalescing(
  // while dragging: without velocities and accelerations (a smaller answer); on release: all
  (req) => { const t0 = performance.now(); return call("/api/simulate", { mechanism: req.mech, steps: stepsFor(req.mech), rates: !req.drag }).then((r) => ({ r, ms: performance.now() - t0 })); },
  ({ r, ms }, { mech, t0, edited }) => {
    state.simulations += 1;
    state.lastSimMs = ms;
    checkAfterSim(mech);
    if (mech !== state.mech && !state.dragging) return; // a newer mechanism is on its way
    state.sim = r; state.simFor = mech; state.errors = []; state.notes = r.notes || [];
    const home = homeOf(r);
    if (state.frame === state.home || state.frame >= r.assembled.length) state.frame = home;
    state.home = home;
    render();
    // drag-to-repaint latency: from the pointer event to the frame that shows its simulation
    if (t0 !== undefined) requestAnimationFrame(() => state.latencies.push(performance.now() - t0));
    if (edited !== undefined) requestAnimationFrame(() => state.editLatencies.push(performance.now() - edited));
    if (!state.dragging) renderAnalysis();
  },
  (e, { mech }) => {
    state.simulations += 1;
    checkAfterSim(mech);
    if (mech !== state.mech && !state.dragging) return;
    state.sim = null; state.simFor = mech; state.notes = [];
    state.errors = [{ message: e.error || String(e), hint: e.hint, field: e.field, element: e.element }];
    render(); renderAnalysis();
  });

// The check deferred by setMech until the edited mechanism's first simulation answer.
function checkAfterSim(mech) {
  if (!state.afterSim || mech !== state.mech) return;
  const run = state.afterSim; state.afterSim = null; run();
}

let analyseTimer = null;
function analyseSoon() {
  clearTimeout(analyseTimer);
  analyseTimer = setTimeout(async () => {
    const mech = state.mech;
    try {
      const a = await call("/api/analyze", { mechanism: mech });
      if (mech !== state.mech) return;
      a.groupOf = {};
      if (a.assur) [...a.assur.initial_mechanisms, ...a.assur.groups].forEach((g, i) => g.links.forEach((l) => (a.groupOf[l] = i)));
      state.analysis = a;
    } catch (e) {
      state.analysis = { error: e.error || String(e), hint: e.hint };
    }
    renderAnalysis(); render();
    if (spatial() && $("tab-forces").classList.contains("on")) forcesUi.renderForces(); // the rank reading
  }, 250);
}

function setMech(mech, { record = true, fit = false, keepFrame = false, opened = false, edited } = {}) {
  if (record && state.mech) { state.undo.push(JSON.stringify(state.mech)); state.redo = []; }
  if (opened) state.dirty = false;
  else if (state.mech && mech.joints.length) { state.dirty = true; if (root === document) autosave(mech, state.fileName); }
  state.mech = mech;
  view3d.open(mech); // view3d: a spatial file's sweep for the 3-D view
  if (onChange) onChange(mech);
  if (!keepFrame) state.frame = state.home;
  if (fit) fitView();
  state.errors = [];
  const key = checkKey(mech), topo = topologyKey(mech);
  if (state.check && state.check.key === key) { state.afterSim = null; afterCheck(mech, state.check.result, edited); }
  else {
    // the server's check (mobility, drives, connections) runs again on every change it reads.
    // Only the places changed and the last check let it move: simulated at once meanwhile,
    // re-done if the new check says otherwise (a four-bar moved onto one line cannot be driven)
    const prev = state.check && state.check.topo === topo && !state.check.result.diagnostics.some((d) => d.blocks) ? state.check.result : null;
    if (prev) afterCheck(mech, prev, edited); else state.diagnostics = geometryChecks(mech);
    state.check = null;
    // (asked once the repaint's simulation is back: the two would share the server's cores)
    const later = prev && mech.joints.some((j) => j.actuated);
    state.afterSim = later ? () => runCheck(mech, key, topo, prev, edited) : null;
    if (!later) runCheck(mech, key, topo, prev, edited);
  }
  analyseSoon();
  render();
  renderElement();
  if ($("tab-forces").classList.contains("on")) { forcesUi.renderForces(); forcesUi.forcesSoon(); }
  if (spatial()) renderPlots(); // the spatial plots' sweep (asked for while the Plots tab is shown)
}

// The server's check of `mech`; its answer replaces `prev` (the answer simulated meanwhile) when they differ.
function runCheck(mech, key, topo, prev, edited) {
  call("/api/studio/check", { mechanism: mech }).then((result) => {
    if (mech !== state.mech) return;
    state.check = { key, topo, result };
    if (!prev || JSON.stringify(result) !== JSON.stringify(prev)) { afterCheck(mech, result, prev ? undefined : edited); render(); }
  }, (e) => {
    if (mech !== state.mech) return;
    state.sim = null; state.simFor = mech; state.notes = [];
    state.errors = [{ message: e.error || String(e), hint: e.hint, field: e.field, element: e.element }];
    render(); renderAnalysis();
  });
}

// Simulate unless the checks say it is pointless (a structure, drives that fight, loose parts).
// An edit's first answer leaves out the rates (the repaint comes sooner, as in a drag); the full
// simulation follows it.
function afterCheck(mech, result, edited) {
  state.diagnostics = result.diagnostics.concat(geometryChecks(mech));
  state.notes = [];
  if (result.diagnostics.some((d) => d.blocks)) { state.sim = null; state.simFor = mech; renderAnalysis(); }
  else if (mech.joints.some((j) => j.actuated)) {
    if (edited !== undefined) simulateSoon({ mech, drag: true, edited });
    simulateSoon({ mech });
  }
  else { state.sim = null; state.simFor = mech; state.notes = mech.joints.length ? ["no drive yet: mark a joint with Drive to move it"] : ["empty: add ground pivots, then links"]; }
}

// One numeric edit: fn changes a copy of the mechanism (at the drawn pose); re-simulated, one undo step.
function edit(fn) { const t0 = performance.now(); const m = rebase(); fn(m); setMech(m, { edited: t0 }); }

// The drawn pose becomes the file's pose (the branch drawn is the one kept).
function rebase() {
  const { sim, frame: k } = state;
  if (!sim || k === state.home || !sim.assembled[k]) return clone(state.mech);
  const m = clone(state.mech);
  const at = (n) => sim.points[n] && sim.points[n].position[k];
  for (const j of m.joints) if (at(j.id)) j.point = at(j.id).slice();
  for (const [n, p] of Object.entries(m.points || {})) if (at(n)) p.at = at(n).slice();
  state.frame = state.home;
  return m;
}

// ------------------------------------------------------------------ view
function fitView() {
  const m = state.mech;
  const pts = m ? m.joints.map((j) => j.point).concat(Object.values(m.points || {}).map((p) => p.at)) : [];
  if (state.sim) for (const ps of Object.values(state.sim.points)) for (const p of ps.position) if (p) pts.push(p);
  if (!pts.length) { state.view = { s: 60, ox: 3, oy: 2 }; return; }
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...xs), Math.max(...xs), Math.min(...ys), Math.max(...ys)];
  const r = svg.getBoundingClientRect();
  const s = Math.min((r.width || 800) / Math.max(x1 - x0, 1e-9), (r.height || 600) / Math.max(y1 - y0, 1e-9)) * 0.7;
  state.view = { s: Math.min(Math.max(s, 1e-3), 1e6), ox: (x0 + x1) / 2, oy: (y0 + y1) / 2 };
}

function worldAt(ev) {
  const r = svg.getBoundingClientRect();
  let p = makeView(svg, state.view).toWorld([ev.clientX - r.left, ev.clientY - r.top]);
  if (state.opts.snap) { const g = gridStep(state.view); p = p.map((c) => Math.round(c / g) * g); }
  return p.map((c) => tidy(c, state.view.s));
}

// ------------------------------------------------------------------ naming
function nextJointId(m) {
  const used = new Set(m.joints.map((j) => j.id).concat(Object.keys(m.points || {})));
  for (const c of "ABCDEFGHIJKLMNOQRSTUVWXYZ") if (!used.has(c)) return c;
  for (let i = 1; ; i++) if (!used.has(`J${i}`)) return `J${i}`;
}
function nextLinkName(m) {
  const used = new Set(m.links.map(linkName));
  for (let i = 1; ; i++) if (!used.has(`L${i}`)) return `L${i}`;
}
function nextPointName(m) {
  const used = new Set(m.joints.map((j) => j.id).concat(Object.keys(m.points || {})));
  for (const c of ["P", "M", "Q", "R", "S"]) if (!used.has(c)) return c;
  for (let i = 1; ; i++) if (!used.has(`P${i}`)) return `P${i}`;
}

// ------------------------------------------------------------------ editing
function addPivot(p) {
  const m = rebase();
  m.joints.push({ id: nextJointId(m), type: "R", links: [m.ground], point: p });
  setMech(m);
}

function finishLink() {
  const picks = state.building;
  state.building = [];
  $("finish-link").disabled = true;
  if (picks.length < 2) { render(); return; }
  const m = rebase();
  const name = nextLinkName(m);
  m.links.push(name);
  for (const pick of picks) {
    const j = pick.joint && m.joints.find((x) => x.id === pick.joint);
    if (!j) m.joints.push({ id: nextJointId(m), type: "R", links: [name], point: pick.point });
    else if (j.links.length < 2) j.links.push(name);
    else m.joints.push({ id: nextJointId(m), type: "R", links: [j.links[0] === m.ground ? j.links[1] : j.links[0], name], point: j.point.slice() });
  }
  setMech(m);
}

function segDist(p, a, b) {
  const dx = b[0] - a[0], dy = b[1] - a[1], L = dx * dx + dy * dy || 1e-12;
  const t = Math.max(0, Math.min(1, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / L));
  return Math.hypot(p[0] - a[0] - t * dx, p[1] - a[1] - t * dy);
}

function nearestLink(m, p) {
  const pos = positions(m, null, 0), mem = membership(m);
  let best = null, bd = Infinity;
  for (const [name, g] of Object.entries(mem)) {
    if (name === m.ground) continue;
    const pts = g.joints.map((id) => pos.joints[id]);
    for (let i = 0; i < pts.length; i++) for (let k = i + 1; k < pts.length; k++) {
      const d = segDist(p, pts[i], pts[k]);
      if (d < bd) { bd = d; best = name; }
    }
  }
  return best;
}

function addPoint(p) {
  const m = rebase();
  const link = nearestLink(m, p);
  if (!link) { state.errors = [{ message: "a point needs a moving link: add a link first" }]; render(); return; }
  m.points = m.points || {};
  m.points[nextPointName(m)] = { link, at: p };
  setMech(m);
}

function toggleDrive(id) {
  const m = rebase();
  const j = m.joints.find((x) => x.id === id);
  if (j.actuated) delete j.actuated; else j.actuated = true;
  setMech(m);
}

function deleteJoint(id) {
  const m = rebase();
  m.joints = m.joints.filter((j) => j.id !== id);
  setMech(m);
}
function deletePoint(name) {
  const m = rebase();
  delete m.points[name];
  setMech(m);
}
function deleteLink(name) {
  const m = rebase();
  if (name === m.ground) return;
  m.links = m.links.filter((l) => linkName(l) !== name);
  for (const j of m.joints) j.links = j.links.filter((l) => l !== name);
  m.joints = m.joints.filter((j) => j.links.length > 0);
  for (const [n, p] of Object.entries(m.points || {})) if (p.link === name) delete m.points[n];
  setMech(m);
}

function undo() { if (!state.undo.length) return; state.redo.push(JSON.stringify(state.mech)); setMech(JSON.parse(state.undo.pop()), { record: false }); }
function redo() { if (!state.redo.length) return; state.undo.push(JSON.stringify(state.mech)); setMech(JSON.parse(state.redo.pop()), { record: false }); }

// ------------------------------------------------------------------ pointer interaction
// The joints drawn within 8 px of the pointer, topmost first (a slider's R joint over its P joint).
function jointsAt(ev) {
  const r = svg.getBoundingClientRect(), v = makeView(svg, state.view), pos = positions(state.mech, state.sim, state.frame);
  const near = state.mech.joints.filter((j) => {
    const q = v.toScreen(pos.joints[j.id]);
    return Math.hypot(q[0] - (ev.clientX - r.left), q[1] - (ev.clientY - r.top)) <= 8;
  });
  return near.sort((a, b) => (a.type === "P") - (b.type === "P")).map((j) => j.id);
}
// The joint a click means: where several coincide, the next after the selected one (clicks cycle);
// in Drive and Delete, the selected one of them.
function pickJoint(ev, hitId, cycle) {
  const ids = jointsAt(ev);
  if (hitId && !ids.includes(hitId)) ids.unshift(hitId);
  if (ids.length < 2) return hitId || ids[0] || null;
  const cur = state.selected && state.selected.kind === "joint" ? ids.indexOf(state.selected.id) : -1;
  if (cur < 0) return hitId || ids[0];
  return cycle ? ids[(cur + 1) % ids.length] : ids[cur];
}

let gesture = null;
svg.addEventListener("pointerdown", (ev) => {
  if (!state.mech) return;
  const t = ev.target;
  const jointEl = t.closest("[data-joint]"), pointEl = t.closest("[data-point]"), linkEl = t.closest("[data-link]");
  const handleEl = t.closest("[data-handle]");
  const p = worldAt(ev);
  const mode = state.mode;
  const jointId = jointEl || (!pointEl && !handleEl) ? pickJoint(ev, jointEl && jointEl.dataset.joint, mode === "select") : null;
  if (mode === "select" && handleEl) { // turning a slider's guide
    state.selected = { kind: "joint", id: handleEl.dataset.handle };
    state.undo.push(JSON.stringify(state.mech)); state.redo = [];
    state.mech = rebase(); state.dragging = true;
    gesture = { kind: "drag", what: "axis", id: handleEl.dataset.handle, moved: false };
    svg.setPointerCapture(ev.pointerId);
    renderElement();
    return;
  }
  if (mode === "select" && (jointId || pointEl)) {
    const kind = jointId ? "joint" : "point", id = jointId || pointEl.dataset.point;
    state.selected = { kind, id };
    const before = JSON.stringify(state.mech);
    const m = rebase();
    const start = kind === "joint" ? m.joints.find((j) => j.id === id).point.slice() : m.points[id].at.slice();
    const together = kind === "joint" ? m.joints.filter((j) => j.point[0] === start[0] && j.point[1] === start[1]).map((j) => j.id) : [];
    state.undo.push(before); state.redo = [];
    state.mech = m; state.dragging = true;
    gesture = { kind: "drag", what: kind, id, together, moved: false };
    svg.setPointerCapture(ev.pointerId);
    renderElement();
    return;
  }
  if (mode === "select" && linkEl && !jointId && !pointEl) { state.selected = { kind: "link", id: linkEl.dataset.link }; render(); renderElement(); }
  if (mode === "select" || (mode !== "select" && ev.button === 1)) {
    gesture = { kind: "pan", x: ev.clientX, y: ev.clientY, view: { ...state.view } };
    svg.setPointerCapture(ev.pointerId);
    return;
  }
  if (mode === "pivot") addPivot(p);
  else if (mode === "link") {
    if (jointEl) { const j = state.mech.joints.find((x) => x.id === jointEl.dataset.joint); state.building.push({ joint: j.id, point: j.point }); }
    else state.building.push({ joint: null, point: p });
    $("finish-link").disabled = state.building.length < 2;
    render();
  } else if (mode === "point") addPoint(p);
  else if (mode === "drive" && jointId) toggleDrive(jointId);
  else if (mode === "delete") {
    if (jointId) deleteJoint(jointId);
    else if (pointEl) deletePoint(pointEl.dataset.point);
    else if (linkEl) deleteLink(linkEl.dataset.link);
  } else if (mode === "target") {
    state.targets.push(p);
    $("target-count").textContent = state.targets.length; synthUi.renderPoses();
    gesture = { kind: "draw", last: [ev.clientX, ev.clientY] };
    svg.setPointerCapture(ev.pointerId);
    render();
  }
});

svg.addEventListener("pointermove", (ev) => {
  if (!gesture) return;
  if (gesture.kind === "draw") { // drawing a target curve: a point every 12 px
    if (Math.hypot(ev.clientX - gesture.last[0], ev.clientY - gesture.last[1]) < 12) return;
    gesture.last = [ev.clientX, ev.clientY];
    state.targets.push(worldAt(ev));
    $("target-count").textContent = state.targets.length; synthUi.renderPoses();
    render();
    return;
  }
  if (gesture.kind === "pan") {
    const s = state.view.s;
    state.view = { ...gesture.view, ox: gesture.view.ox - (ev.clientX - gesture.x) / s, oy: gesture.view.oy + (ev.clientY - gesture.y) / s };
    render();
    return;
  }
  const p = worldAt(ev);
  const m = clone(state.mech);
  if (gesture.what === "axis") {
    const j = m.joints.find((q) => q.id === gesture.id);
    const deg = (Math.atan2(p[1] - j.point[1], p[0] - j.point[0]) * 180) / Math.PI;
    j.axis = axisOf(Math.round(deg * 10) / 10);
  } else if (gesture.what === "joint") for (const j of m.joints) { if (gesture.together.includes(j.id)) j.point = p.slice(); }
  else m.points[gesture.id].at = p;
  gesture.moved = true;
  state.mech = m;
  if (state.check) state.diagnostics = state.check.result.diagnostics.concat(geometryChecks(m));
  render();
  simulateSoon({ mech: m, drag: true, t0: ev.timeStamp });
});

function endGesture() {
  if (!gesture) return;
  const g = gesture;
  gesture = null;
  if (g.kind === "drag") {
    state.dragging = false;
    if (!g.moved) state.undo.pop();
    setMech(clone(state.mech), { record: false });
  }
}
svg.addEventListener("pointerup", endGesture);
svg.addEventListener("pointercancel", endGesture);

svg.addEventListener("wheel", (ev) => {
  ev.preventDefault();
  const r = svg.getBoundingClientRect();
  const v = makeView(svg, state.view);
  const before = v.toWorld([ev.clientX - r.left, ev.clientY - r.top]);
  const s = state.view.s * Math.exp(-ev.deltaY * 0.0015);
  state.view = { s, ox: before[0] - (ev.clientX - r.left - v.W / 2) / s, oy: before[1] + (ev.clientY - r.top - v.H / 2) / s };
  render();
}, { passive: false });

// ------------------------------------------------------------------ side panels

function renderAnalysis() { // analysis.js: the result first, the specialist notes folded
  $("tab-analysis").replaceChildren(...analysisTab({ a: state.analysis, sim: state.sim, errors: state.errors, mech: state.mech, diagnostics: state.diagnostics }));
}

function renderElement() {
  renderJoints();
  const box = $("tab-element"), sel = state.selected, m = state.mech;
  if (!sel || !m) { box.replaceChildren(h("p", "Click a joint or point with Select to edit it (clicking again where joints coincide selects the next).", { className: "muted" })); return; }
  const out = [];
  if (sel.kind === "link") return designUi.linkElement(box, m, sel.id);
  if (sel.kind === "joint") {
    const j = m.joints.find((x) => x.id === sel.id);
    if (!j) { state.selected = null; return renderElement(); }
    if (m.kind !== "planar") return spatialElement(box, m, j);
    out.push(h("h3", `Joint ${j.id} (${j.type === "P" ? "slider, P" : "pin, R"})`));
    const type = h("select"); for (const t of ["R", "P"]) type.append(h("option", t, { value: t, selected: j.type === t }));
    type.id = "joint-type";
    type.onchange = () => edit((n) => setType(n.joints.find((q) => q.id === j.id), type.value));
    const drive = h("input", null, { type: "checkbox", checked: !!j.actuated, id: "joint-drive" });
    drive.onchange = () => toggleDrive(j.id);
    const links = h("input", null, { value: j.links.join(", "), id: "joint-links", size: 20 });
    links.onchange = () => edit((n) => setLinks(n, j.id, links.value));
    const row = (label, ...els) => { const p = h("p"); p.append(h("label", label + " "), ...els); return p; };
    out.push(...jointFields(j, edit), row("pair type", type), row("links", links), row("drive", drive));
    if (j.type === "P") out.push(designUi.guideRows(m, j.id)); // issue 40: the guide's offset and angle
    const del = h("button", "Delete joint"); del.onclick = () => deleteJoint(j.id); out.push(del);
  } else {
    const p = (m.points || {})[sel.id];
    if (!p) { state.selected = null; return renderElement(); }
    out.push(h("h3", `Point ${sel.id} on ${p.link}`), ...pointFields(sel.id, p, edit));
    const del = h("button", "Delete point"); del.onclick = () => deletePoint(sel.id); out.push(del);
  }
  box.replaceChildren(...out);
}

// The Element tab of a spatial file's joint: its type, links and drive, its point and axis as
// numbers (an edit re-runs the 3-D sweep and the check: a joint moved off a special geometry that
// let the mechanism move is explained in the banner).
function spatialElement(box, m, j) {
  const row = (label, ...els) => { const p = h("p"); p.append(h("label", label + " "), ...els); return p; };
  const drive = h("input", null, { type: "checkbox", checked: !!j.actuated, id: "joint-drive" });
  drive.onchange = () => toggleDrive(j.id);
  const out = [h("h3", `Joint ${j.id}: ${j.type} pair (${PAIR_NAMES[j.type] || j.type})`),
    row("joins", h("span", j.links.join(" and "), { id: "joint-links" })), ...spatialJointFields(m, j, edit), row("drive", drive),
    h("p", "The point and axes are those of the drawn pose (input 0 on the slider); an edit re-runs the sweep and the check from there.", { className: "muted" })];
  box.replaceChildren(...out);
}

function renderJoints() {
  const m = state.mech;
  if (!m) return;
  const sel = state.selected && state.selected.kind === "joint" ? state.selected.id : null;
  $("tab-joints").replaceChildren(...jointTable(m, sel, edit, (id) => { state.selected = { kind: "joint", id }; render(); renderElement(); }, designUi.setLength));
}

function renderPlots() { if (spatial()) spatialUi.renderPlots(); else planarPlots(); } // plots.js: the planar charts

// ------------------------------------------------------------------ player, synthesis, atlas
const designUi = mountDesign({ $, root, state, render, setMech, rebase, setMode: (m) => setMode(m), showTab: (t) => showTab(t) });
const setPlaying = mountPlayer({ $, state, render, assembledNear });
const planarPlots = mountPlots({ $, state, render, assembledNear });
const synthUi = mountSynthesis({ $, state, render, setMech, setMode: (m) => setMode(m), design: designUi });
mountAtlas({ $, state, render, setMech });
const spatialUi = mountSpatialTabs({ $, state, render, showTab, motionOf: view3d.motionOf });
const forcesUi = mountForces({ $, state, render, edit, stepsFor, spatialLines: spatialUi.forcesLines });

// ------------------------------------------------------------------ files
const { openFrom, refreshFiles } = mountFiles({ $, svg, state, render, setMech, fitView });

// ------------------------------------------------------------------ toolbar, keys, start
function setMode(mode) {
  state.mode = mode;
  if (mode !== "link") { state.building = []; $("finish-link").disabled = true; }
  for (const b of root.querySelectorAll("#modes button")) b.classList.toggle("on", b.dataset.mode === mode);
  if (mode === "target") showTab("synthesis");
  render();
}
function showTab(name) {
  for (const b of root.querySelectorAll("#tabs button")) b.classList.toggle("on", b.dataset.tab === name);
  for (const t of root.querySelectorAll(".tab")) t.classList.toggle("on", t.id === `tab-${name}`);
  if (name === "plots") renderPlots();
  if (name === "forces") { forcesUi.renderForces(); forcesUi.compute(); }
  render();
}
for (const b of root.querySelectorAll("#modes button")) b.onclick = () => setMode(b.dataset.mode);
for (const b of root.querySelectorAll("#tabs button")) b.onclick = () => showTab(b.dataset.tab);
$("finish-link").onclick = finishLink;
$("undo").onclick = undo;
$("redo").onclick = redo;
$("new").onclick = () => { state.fileName = ""; $("save-name").value = ""; state.selected = null; state.sim = null; setMech(EMPTY(), { fit: true }); }; // fit: the default zoom
if (root === document) guardUnload(() => state.dirty);
$("fit").onclick = () => { fitView(); render(); };
$("grid").onchange = (ev) => { state.opts.grid = ev.target.checked; render(); };
$("snap").onchange = (ev) => { state.opts.snap = ev.target.checked; };
$("assur-colours").onchange = (ev) => { state.opts.assurColours = ev.target.checked; render(); };
$("plot-what").onchange = renderPlots;
$("drive-speed").onchange = () => { renderPlots(); forcesUi.forcesSoon(); };
window.addEventListener("resize", render);
bindKeys(root, {
  undo, redo, finishLink, setMode, play: () => setPlaying(!state.playing), fit: () => { fitView(); render(); }, step: setPlaying.step,
  escape: () => { state.building = []; setMode("select"); }, linkMode: () => state.mode === "link",
  deleteSelection: () => { const sel = state.selected; if (!sel) return; state.selected = null; (sel.kind === "joint" ? deleteJoint : deletePoint)(sel.id); },
}, { contained: root !== document });

(async function start() {
  try {
    const s = await call("/api/start");
    $("save-name").value = s.name || "";
    for (const [k, title] of Object.entries(s.synthesis_kinds || {})) $("synth-kind").append(h("option", title, { value: k }));
    const ex = await call("/api/studio/examples");
    fillExamples($("examples"), $("examples-search"), ex.examples, (name) => { $("examples").value = name; $("examples").dispatchEvent(new Event("change")); });
    refreshFiles();
    if (s.mechanism) openFrom(Promise.resolve({ mechanism: s.mechanism, name: s.name }));
    else setMech(EMPTY(), { record: false, fit: true });
    const w = root === document ? savedWork() : null;
    if (w && JSON.stringify(w.mechanism) !== JSON.stringify(s.mechanism)) { state.offer = w; render(); }
  } catch (e) {
    state.fatal = startProblem(e);
    state.mech = EMPTY(); render();
  }
})();
}
