// The 3-D view of spatial mechanisms: the server's spatial kinematics (/api/spatial/simulate,
// web/_spatial.py: the SpatialSimulation's to_dict, as `mechsyn simulate --json`) drawn in SVG, orthographic or perspective, orbit (drag), zoom (wheel),
// reset (button or double-click). Joints by type (R, C, H: a short shaft along the axis;
// P: a block along its slide; S: a ball; U: the crossed arms), links as bars (plates for
// three joints or more, the convex outline of their joints), the frame dashed with ground
// marks, everything sorted by depth. Each joint is one element with data-joint, each link
// one with data-link, each point path one with data-path. The studio's input slider moves
// the mechanism through the simulated rows; rows not assembled and the sweep's events
// (singular positions, dead points, reassembly) are told in the [data-banner].
import { call } from "./api.js";
import { el, GROUP_COLOURS } from "./draw.js";

const HOME = { az: (-60 * Math.PI) / 180, el: (22 * Math.PI) / 180 };
const sub = (a, b) => [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
const add = (a, b, f = 1) => [a[0] + f * b[0], a[1] + f * b[1], a[2] + f * b[2]];
const dot = (a, b) => a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
const cross = (a, b) => [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]];
const unit = (a) => { const n = Math.hypot(...a) || 1; return a.map((c) => c / n); };

// Two unit vectors square to a (for a slider's block).
function across(a) {
  const u = unit(cross(a, Math.abs(a[2]) < 0.9 ? [0, 0, 1] : [1, 0, 0]));
  return [u, cross(a, u)];
}

// The convex outline (monotone chain) of screen points [x, y, ...].
function hull(pts) {
  const p = pts.slice().sort((a, b) => a[0] - b[0] || a[1] - b[1]);
  if (p.length < 3) return p;
  const side = (o, a, b) => (a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]);
  const half = (list) => { const h = []; for (const q of list) { while (h.length > 1 && side(h[h.length - 2], h[h.length - 1], q) <= 0) h.pop(); h.push(q); } h.pop(); return h; };
  return half(p).concat(half(p.slice().reverse()));
}

// The camera: azimuth and elevation about the scene's centre, a scale (px per unit) and,
// for perspective, the eye at 4 radii from the centre.
function camera(cam, W, H) {
  const ca = Math.cos(cam.az), sa = Math.sin(cam.az), ce = Math.cos(cam.el), se = Math.sin(cam.el);
  const d = [ce * ca, ce * sa, se], right = [-sa, ca, 0], up = cross(d, right);
  const D = 4 * cam.radius;
  return (p) => {
    const q = sub(p, cam.centre), depth = dot(q, d);
    const f = cam.perspective ? D / Math.max(D - depth, 1e-9 * D) : 1;
    return [W / 2 + cam.s * f * dot(q, right), H / 2 - cam.s * f * dot(q, up), depth, f];
  };
}

// The scene at every row (sceneOf): the simulation `motion` (every moving link's pose over the
// rows, x = rotation x0 + translation) placed on the file `mech`: each joint's position (carried
// by its second link) and axes (its axis by its first link, a U joint's axis2 by its second;
// `mechsyn.plot.spatial.joint_frames` draws them the same way), the paths of the named points
// (else of every joint off the frame), the row of the drawn pose (`home`: the middle row of a P
// or C drive's sweep) and the largest closure residual. The rest of the motion (input, assembled,
// events, notes, length_scale) is passed on; `joints` here is the joints' geometry (the motion's
// pair values stay under `pairs`).
export function sceneOf(motion, mech) {
  const n = motion.assembled.length, I = [[1, 0, 0], [0, 1, 0], [0, 0, 1]], O = [0, 0, 0];
  const pose = (link, k) => { const l = motion.links[link]; return !l ? [I, O] : l.rotation[k] ? [l.rotation[k], l.translation[k]] : null; };
  const apply = (R, x, t = O) => [0, 1, 2].map((i) => R[i][0] * x[0] + R[i][1] * x[1] + R[i][2] * x[2] + t[i]);
  const joints = mech.joints.filter((j) => j.point).map((j) => {
    const position = [], axes = [];
    for (let k = 0; k < n; k++) {
      const a = pose(j.links[0], k), b = pose(j.links[1] || j.links[0], k);
      if (!motion.assembled[k] || !a || !b) { position.push(null); axes.push(null); continue; }
      position.push(apply(b[0], j.point, b[1]));
      axes.push([j.axis && apply(a[0], unit(j.axis)), j.axis2 && apply(b[0], unit(j.axis2))].filter(Boolean));
    }
    return { id: j.id, type: j.type, links: j.links, actuated: !!j.actuated, position, axes };
  });
  const named = Object.keys(mech.points || {});
  const shown = named.length ? named : mech.joints.filter((j) => j.point && !j.links.includes(mech.ground)).map((j) => j.id);
  const linkOf = (name) => (named.includes(name) ? mech.points[name].link : mech.joints.find((j) => j.id === name).links[1]);
  const paths = Object.fromEntries(shown.filter((p) => motion.points[p]).map((p) => [p, { link: linkOf(p), position: motion.points[p].position }]));
  const res = motion.residual.filter((r, k) => r !== null && motion.assembled[k]);
  return { ...motion, pairs: motion.joints, joints, paths, links: mech.links.map((l) => (typeof l === "string" ? l : l.name)), ground: mech.ground,
    home: ["P", "C"].includes(motion.input.type) ? n >> 1 : 0, residual: res.length ? Math.max(...res) : null };
}

export function mountView3d({ $, state, svg: canvas, render, select }) {
  const svg = el("svg", { id: "view3d", role: "img", "aria-label": "3-D view of the spatial mechanism" });
  Object.assign(svg.style, { width: "100%", height: "100%", display: "none", background: "#fff", touchAction: "none", userSelect: "none", cursor: "move" });
  canvas.after(svg);
  const bar = document.createElement("div");
  Object.assign(bar.style, { position: "absolute", right: "8px", bottom: "8px", display: "none", gap: "6px", alignItems: "center" });
  const reset = document.createElement("button"), persp = document.createElement("input"), lab = document.createElement("label");
  reset.textContent = "Reset view"; reset.id = "view3d-reset"; reset.title = "Back to the first view (double-click)";
  persp.type = "checkbox"; persp.id = "view3d-perspective";
  lab.append(persp, " perspective");
  const axesBox = document.createElement("input"), axesLab = document.createElement("label");
  axesBox.type = "checkbox"; axesBox.id = "view3d-axes"; axesBox.checked = true;
  axesLab.append(axesBox, " axis lines");
  axesLab.title = "Draw the axes of the R, C and H pairs as lines (a spherical linkage's meet at its centre)";
  bar.append(axesLab, lab, reset);
  canvas.parentNode.append(bar);

  const v3 = { view: null, mech: null, key: "", error: null, loading: false, cam: null, gesture: null, draws: 0, playing: false };
  window.__view3d = v3; // for tests (read-only use)
  const shown = () => !!(v3.view && state.mech === v3.mech && state.mech.kind !== "planar");

  function fit() {
    const pts = [];
    for (const j of v3.view.joints) for (const p of j.position) if (p) pts.push(p);
    const lo = [0, 1, 2].map((i) => Math.min(...pts.map((p) => p[i]))), hi = [0, 1, 2].map((i) => Math.max(...pts.map((p) => p[i])));
    const centre = lo.map((c, i) => (c + hi[i]) / 2);
    const radius = Math.max(...pts.map((p) => Math.hypot(...sub(p, centre))), 1e-9 * v3.view.length_scale);
    const r = svg.getBoundingClientRect();
    v3.cam = { ...HOME, centre, radius, s: (0.42 * Math.min(r.width || 800, r.height || 600)) / radius, perspective: persp.checked };
  }

  // ---- the sweep from the server, once per mechanism: one request for the view and the Plots tab
  let asked = { key: "", motion: null };
  function motionOf(mech) {
    const key = JSON.stringify(mech);
    if (asked.key !== key) {
      const motion = call("/api/spatial/simulate", { mechanism: mech });
      motion.catch(() => { if (asked.motion === motion) asked = { key: "", motion: null }; }); // asked again later
      asked = { key, motion };
    }
    return asked.motion;
  }

  function open(mech) {
    if (!mech || mech.kind === "planar") { v3.key = ""; v3.view = null; v3.error = null; show(false); return; }
    const key = JSON.stringify(mech);
    if (key === v3.key) { v3.mech = mech; return; }
    // an edit of the mechanism shown keeps its picture (and the camera) until the new sweep comes
    const ids = (m) => m.name + ":" + m.joints.map((j) => j.id).join();
    const same = !!(v3.view && v3.mech && ids(v3.mech) === ids(mech));
    v3.key = key; v3.error = null; v3.loading = true;
    if (!same) v3.view = null;
    v3.mech = mech;
    motionOf(mech).then((motion) => {
      if (v3.key !== key) return;
      const view = sceneOf(motion, mech);
      v3.view = view; v3.loading = false;
      if (!same || !v3.cam) { show(true); fit(); }
      state.frame = view.home;
      render();
    }, (e) => {
      if (v3.key !== key) return;
      v3.view = null; v3.loading = false; v3.error = e;
      render();
    });
  }

  function show(on) {
    svg.style.display = on ? "block" : "none";
    bar.style.display = on ? "flex" : "none";
    canvas.style.display = on ? "none" : "block";
    if (on) canvas.replaceChildren(); // one data-joint element per joint on the page
  }

  // The row drawn: the slider's, or where it is not assembled the nearest assembled one.
  function rowOf(k) {
    const ok = v3.view.assembled;
    k = Math.max(0, Math.min(ok.length - 1, k | 0));
    for (let d = 0; d < ok.length; d++) { if (ok[k - d]) return k - d; if (ok[k + d]) return k + d; }
    return -1;
  }
  const inputText = (k) => { const i = v3.view.input; return `${i.joint} = ${(+i.values[k]).toFixed(i.unit === "deg" ? 1 : 3)}${i.unit === "deg" ? "°" : ""}`; };

  // ---- drawing
  function draw() {
    const view = v3.view, k = rowOf(state.frame);
    svg.replaceChildren();
    if (k < 0) return;
    const r = svg.getBoundingClientRect(), W = r.width || 800, H = r.height || 600;
    const P = camera(v3.cam, W, H), L = view.length_scale, pos = {}, scr = {};
    for (const j of view.joints) { pos[j.id] = j.position[k]; scr[j.id] = P(pos[j.id]); }
    const colour = (name) => (name === view.ground ? "#667" : GROUP_COLOURS[view.links.indexOf(name) % GROUP_COLOURS.length]);
    const items = []; // [depth, element]
    const paths = el("g", { class: "view3d-paths" }, svg);
    for (const [name, p] of Object.entries(view.paths)) {
      let d = "", pen = false;
      for (const q of p.position) {
        if (!q) { pen = false; continue; }
        const s = P(q);
        d += `${pen ? "L" : "M"}${s[0].toFixed(1)} ${s[1].toFixed(1)}`;
        pen = true;
      }
      el("path", { d, "data-path": name, fill: "none", stroke: colour(p.link || view.links[1]), "stroke-width": 1.2, "stroke-opacity": 0.55 }, paths);
    }
    for (const name of view.links) {
      const js = view.joints.filter((j) => j.links.includes(name)).map((j) => j.id);
      if (js.length < 2) continue;
      const depth = js.reduce((a, id) => a + scr[id][2], 0) / js.length;
      const pts = js.map((id) => scr[id]);
      let e;
      if (name === view.ground) {
        e = el("polyline", { points: (pts.length > 2 ? hull(pts).concat([hull(pts)[0]]) : pts).map((s) => `${s[0].toFixed(1)},${s[1].toFixed(1)}`).join(" "),
          fill: "none", stroke: "#889", "stroke-width": 2, "stroke-dasharray": "6 4", class: "frame" });
      } else if (pts.length === 2) {
        e = el("line", { x1: pts[0][0].toFixed(1), y1: pts[0][1].toFixed(1), x2: pts[1][0].toFixed(1), y2: pts[1][1].toFixed(1),
          stroke: colour(name), "stroke-width": 7, "stroke-linecap": "round" });
      } else {
        e = el("polygon", { points: hull(pts).map((s) => `${s[0].toFixed(1)},${s[1].toFixed(1)}`).join(" "),
          fill: colour(name), "fill-opacity": 0.35, stroke: colour(name), "stroke-width": 3, "stroke-linejoin": "round" });
      }
      e.setAttribute("data-link", name);
      items.push([depth, e]);
    }
    const sel = state.selected && state.selected.kind === "joint" ? state.selected.id : null;
    for (const j of view.joints) items.push([scr[j.id][2] + 1e-3 * L, jointElement(j, pos[j.id], (j.axes || [])[k] || [], P, L, j.id === sel)]);
    items.sort((a, b) => a[0] - b[0]);
    for (const [, e] of items) svg.append(e);
    declutter();
    triad(W, H);
    v3.draws += 1;
  }

  function jointElement(j, p, axes, P, L, selected) {
    const g = el("g", { "data-joint": j.id, class: `view3d-joint type-${j.type}` });
    const ink = j.actuated ? "#e07000" : "#123";
    const c = P(p);
    if (selected) el("circle", { cx: c[0].toFixed(1), cy: c[1].toFixed(1), r: 16, class: "selection-ring" }, g);
    const line = (a, b, attrs) => el("line", { x1: a[0].toFixed(1), y1: a[1].toFixed(1), x2: b[0].toFixed(1), y2: b[1].toFixed(1), ...attrs }, g);
    const h = 0.1 * L * (j.type === "C" ? 1.6 : 1);
    if (j.type === "S" || !axes.length) {
      const rad = Math.max(5, v3.cam.s * c[3] * 0.035 * L);
      el("circle", { cx: c[0].toFixed(1), cy: c[1].toFixed(1), r: rad.toFixed(1), fill: "#fff", stroke: ink, "stroke-width": 2 }, g);
      el("circle", { cx: (c[0] - rad / 3).toFixed(1), cy: (c[1] - rad / 3).toFixed(1), r: (rad / 3).toFixed(1), fill: "#dde4ec" }, g);
    } else if (j.type === "P") {
      const a = unit(axes[0]), [u, w] = across(a), half = [0.09 * L, 0.035 * L, 0.035 * L];
      line(P(add(p, a, -2.2 * half[0])), P(add(p, a, 2.2 * half[0])), { stroke: "#889", "stroke-width": 2 });
      const corners = [];
      for (const sa of [-1, 1]) for (const su of [-1, 1]) for (const sw of [-1, 1]) corners.push(P(add(add(add(p, a, sa * half[0]), u, su * half[1]), w, sw * half[2])));
      el("polygon", { points: hull(corners).map((s) => `${s[0].toFixed(1)},${s[1].toFixed(1)}`).join(" "), fill: "#dfe6ee", stroke: ink, "stroke-width": 2 }, g);
    } else if (j.type === "U") {
      for (const a of axes) line(P(add(p, a, -h)), P(add(p, a, h)), { stroke: ink, "stroke-width": 5, "stroke-linecap": "round" });
      el("circle", { cx: c[0].toFixed(1), cy: c[1].toFixed(1), r: 4, fill: "#fff", stroke: ink, "stroke-width": 2 }, g);
    } else { // R, C, H: a shaft along the axis (H dashed), the axis as a thin line
      const a = P(add(p, axes[0], -h)), b = P(add(p, axes[0], h));
      if (axesBox.checked) line(P(add(p, axes[0], -2 * v3.cam.radius)), P(add(p, axes[0], 2 * v3.cam.radius)), { stroke: "#99a", "stroke-width": 1, "stroke-dasharray": "8 3 2 3", class: "axis-line" });
      line(a, b, { stroke: ink, "stroke-width": 13, "stroke-linecap": "butt" });
      line(a, b, { stroke: j.type === "C" ? "#c9d6e6" : "#fff", "stroke-width": 9, "stroke-linecap": "butt", "stroke-dasharray": j.type === "H" ? "3 2" : null });
    }
    if (j.links.includes(v3.view.ground)) { // the ground mark: a hatched foot under the joint
      const y = c[1] + 12;
      el("path", { d: `M${c[0] - 9} ${y}h18M${c[0] - 8} ${y + 5}l4 -5M${c[0] - 2} ${y + 5}l4 -5M${c[0] + 4} ${y + 5}l4 -5`, stroke: "#667", "stroke-width": 1.5, fill: "none" }, g);
    }
    el("text", { x: (c[0] + 9).toFixed(1), y: (c[1] - 9).toFixed(1), "font-size": 11, fill: "#345", class: "view3d-label", "data-at": `${c[0]},${c[1]}` }, g, j.id);
    if (selected) g.setAttribute("data-selected", "true");
    return g;
  }

  // joint labels that do not overlap (issue 40: a Delta's platform has six joints close
  // together): each label takes the first free place of a ring of places round its joint
  function declutter() {
    const placed = [], free = (b) => !placed.some((o) => b.x < o.x + o.w && o.x < b.x + b.w && b.y < o.y + o.h && o.y < b.y + b.h);
    for (const t of svg.querySelectorAll("text.view3d-label")) {
      const [cx, cy] = t.dataset.at.split(",").map(Number), w = 7 * t.textContent.length + 2, hh = 12;
      let box = null;
      for (let ring = 1; ring <= 4 && !box; ring++) for (let k = 0; k < 8 && !box; k++) {
        const a = (-Math.PI / 4) + (k * Math.PI) / 4, r = 9 + 11 * (ring - 1);
        const x = cx + r * Math.cos(a) - (Math.cos(a) < -0.1 ? w : Math.cos(a) < 0.1 ? w / 2 : 0), y = cy - r * Math.sin(a) + 4;
        const b = { x, y: y - hh + 2, w, h: hh };
        if (free(b)) box = b;
      }
      if (!box) { t.setAttribute("visibility", "hidden"); continue; } // crowded out: the joint is still drawn
      placed.push(box);
      t.setAttribute("x", box.x.toFixed(1)); t.setAttribute("y", (box.y + box.h - 2).toFixed(1));
    }
  }

  function triad(W, H) { // the axes x, y, z at the lower left corner
    const cam = { ...v3.cam, centre: [0, 0, 0], s: 1, perspective: false };
    const P = camera(cam, 0, 0), o = [40, H - 40], g = el("g", { class: "view3d-triad" }, svg);
    ["x", "y", "z"].forEach((name, i) => {
      const e = [0, 0, 0]; e[i] = 26;
      const s = P(e);
      el("line", { x1: o[0], y1: o[1], x2: (o[0] + s[0]).toFixed(1), y2: (o[1] + s[1]).toFixed(1), stroke: ["#c33", "#393", "#33c"][i], "stroke-width": 2 }, g);
      el("text", { x: (o[0] + 1.2 * s[0]).toFixed(1), y: (o[1] + 1.2 * s[1] + 4).toFixed(1), "font-size": 11, fill: "#333" }, g, name);
    });
  }

  // ---- the banner, the slider and the input's value (after the studio's own)
  function div(cls, text) { const d = document.createElement("div"); d.className = cls; d.textContent = text; return d; }
  function banner() {
    const b = $("banner"), items = [];
    const msg = v3.error ? String(v3.error.error || v3.error) : "";
    // the engine's refusal is told once: by the check's note (web/_spatial.py check_note) when it has
    // it, else here once the check has answered
    if (v3.error && state.check && !(state.diagnostics || []).some((d) => d.message.includes(msg)))
      items.push(div("warn", `3-D view: ${msg}${v3.error.hint ? " — fix: " + v3.error.hint : ""}`));
    else if (v3.loading && !shown()) items.push(div("note", "3-D view: simulating the spatial mechanism…"));
    if (shown()) {
      const view = v3.view, want = Math.max(0, Math.min(view.assembled.length - 1, state.frame | 0)), k = rowOf(want);
      if (k < 0) items.push(div("err", `not assembled at any input of ${view.input.joint}: the links cannot meet`));
      else if (k !== want) items.push(div("note", `not assembled at ${inputText(want)} (outside the working range): shown at ${inputText(k)}, the nearest assembled input`));
      for (const e of view.events) {
        if (Math.abs(e.index - k) > 1) continue;
        const at = Object.entries(e.input).map(([jid, x]) => `${jid} = ${(+x).toFixed(2)}`).join(", ");
        items.push(div(e.kind === "singular" ? "err" : "warn", `${e.kind} at ${at}: ${e.message}`));
      }
      for (const n of view.notes) items.push(div("note", n));
    }
    b.append(...items);
    if (!b.dataset.level && items.length) b.dataset.level = items[0].className;
  }
  function player() {
    const s = $("input-slider"), view = v3.view;
    s.max = view.assembled.length - 1;
    s.value = Math.max(0, Math.min(+s.max, state.frame | 0));
    const k = rowOf(state.frame);
    const res = view.residual === null ? "" : `, closure ≤ ${view.residual.toExponential(0)} L`;
    $("input-value").textContent = k < 0 ? "" : inputText(k);
    s.title = `${view.input.joint} from the drawn pose (${view.input.unit === "deg" ? "degrees" : "length"})`;
    $("status").textContent = `${view.mechanism}: ${view.joints.length} joints, ${view.engine} engine${res}`;
  }
  // Called by the studio's render() after its banner and player: draws the view when shown.
  // The player first: the studio's renderPlayer has just emptied the input's value (it has no
  // planar sweep), and the footer is one line lower without it where the drives' sliders take
  // its width; the picture, centred on the view, is drawn for the footer the page keeps
  // (drawn before it, the whole picture jumped by half the footer's change at every input).
  function update() {
    if (shown()) { show(true); player(); draw(); }
    else if (svg.style.display !== "none") { show(false); play(false); }
    banner();
  }
  // the view's size changed (the window, the drives' sliders arriving, the footer wrapping):
  // drawn again, centred on the new size
  let size = "";
  new ResizeObserver(([e]) => {
    const now = `${e.contentRect.width}x${e.contentRect.height}`;
    if (now !== size && shown()) draw();
    size = now;
  }).observe(svg);

  // ---- orbit, zoom, reset, select
  svg.addEventListener("pointerdown", (ev) => {
    if (!shown()) return;
    const j = ev.target.closest("[data-joint]");
    if (j) { select(j.dataset.joint); return; } // the studio's selection: data-selected and the Element tab
    v3.gesture = { x: ev.clientX, y: ev.clientY, az: v3.cam.az, el: v3.cam.el };
    svg.setPointerCapture(ev.pointerId);
  });
  svg.addEventListener("pointermove", (ev) => {
    const g = v3.gesture;
    if (!g) return;
    v3.cam.az = g.az - (ev.clientX - g.x) * 0.01;
    v3.cam.el = Math.max(-1.55, Math.min(1.55, g.el + (ev.clientY - g.y) * 0.01));
    draw();
  });
  const end = () => { v3.gesture = null; };
  svg.addEventListener("pointerup", end);
  svg.addEventListener("pointercancel", end);
  svg.addEventListener("wheel", (ev) => {
    ev.preventDefault();
    if (!shown()) return;
    v3.cam.s *= Math.exp(-ev.deltaY * 0.0015);
    draw();
  }, { passive: false });
  const home = () => { if (shown()) { fit(); draw(); } };
  svg.addEventListener("dblclick", home);
  reset.onclick = home;
  axesBox.onchange = () => { if (shown()) draw(); };
  persp.onchange = () => { if (v3.cam) { v3.cam.perspective = persp.checked; draw(); } };

  // ---- play (the studio's ▶ button, Space, its speed and ⇄): through the assembled rows, turning
  // round at the ends of a working range, round and round over a full turn
  let timer = null, last = 0;
  function tick(t) {
    if (!v3.playing) return;
    if (t - last >= 1000 / +$("speed").value) {
      last = t;
      const ok = v3.view.assembled, n = ok.length, full = v3.view.input.type !== "P" && ok.every(Boolean);
      let next = state.frame + state.dir;
      if (full) next = (next + n) % n;
      else if (!ok[next]) { state.dir = -state.dir; next = ok[state.frame + state.dir] ? state.frame + state.dir : state.frame; }
      state.frame = next;
      render();
    }
    timer = requestAnimationFrame(tick);
  }
  function play(on) {
    v3.playing = on && shown();
    $("play").textContent = v3.playing ? "❚❚" : "▶";
    cancelAnimationFrame(timer);
    if (v3.playing) timer = requestAnimationFrame(tick);
  }
  $("play").addEventListener("click", (ev) => { if (shown()) { ev.stopImmediatePropagation(); play(!v3.playing); } }, true);
  (canvas.closest(".mechsyn-studio") || document).addEventListener("keydown", (ev) => {
    if (ev.key !== " " || !shown() || (ev.target.matches && ev.target.matches("input:not([type=checkbox]):not([type=range]), textarea, select"))) return;
    ev.preventDefault(); ev.stopImmediatePropagation(); play(!v3.playing);
  }, true);

  return { open, shown, update, motionOf };
}
