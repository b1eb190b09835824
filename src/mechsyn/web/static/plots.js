// Plots a designer reads (uPlot, vendored): every chart of the Plots and Forces tabs has a grid,
// a zero line, a legend in distinct colours whose entries toggle their series, zoom (drag across;
// double-click to zoom out), the working ranges shaded and the dead points marked, a read-out
// ([data-readout]) of the values at the cursor and at the input slider's position (the cursor is
// shared by the charts of a tab), the max, min, mean and RMS of every series over the sweep, and
// the plotted data as CSV.
import uPlot from "./vendor/uPlot.esm.js";
import { pathD, robustRange, wholeTurn } from "./draw.js";
import { h } from "./numeric.js";

// Distinct colours (Tableau 10), one per series in the order given.
export const SERIES_COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2", "#17becf", "#7f7f7f", "#bcbd22"];

export const fmtValue = (v) => (v === null || v === undefined || !Number.isFinite(v) ? "–" : Math.abs(v) >= 1e5 || (v !== 0 && Math.abs(v) < 1e-3) ? v.toExponential(3) : String(+v.toPrecision(4)));

// max, min, mean and RMS of the finite values (the sweep's rows are equally spaced in the input,
// so at a constant drive speed these are the time averages over the rows shown).
export function stats(values) {
  const v = values.filter((y) => y !== null && Number.isFinite(y));
  if (!v.length) return null;
  let max = -Infinity, min = Infinity, sum = 0, sq = 0;
  for (const y of v) { if (y > max) max = y; if (y < min) min = y; sum += y; sq += y * y; }
  return { max, min, mean: sum / v.length, rms: Math.sqrt(sq / v.length), n: v.length };
}

// CSV of columns [{name, values}] (empty cells where a value is not defined).
export function csvOf(columns) {
  const rows = [columns.map((c) => `"${c.name.replace(/"/g, '""')}"`).join(",")];
  const n = Math.max(...columns.map((c) => c.values.length));
  for (let i = 0; i < n; i++) rows.push(columns.map((c) => { const v = c.values[i]; return v === null || v === undefined || !Number.isFinite(v) ? "" : String(v); }).join(","));
  return rows.join("\n") + "\n";
}

export function download(name, text, type = "text/csv") {
  const a = document.createElement("a");
  a.href = URL.createObjectURL(new Blob([text], { type })); a.download = name;
  document.body.append(a); a.click(); a.remove();
  setTimeout(() => URL.revokeObjectURL(a.href), 5000);
}

const nearest = (xs, u) => { let best = 0; xs.forEach((v, i) => { if (Math.abs(v - u) < Math.abs(xs[best] - u)) best = i; }); return best; };

// One chart. `o`: {title, xs, xname (the input's name), xunit, yunit, series [{name, values}], k (the
// slider's row), ranges [[a, b]] (working ranges), marks [{x, kind, text}], onPick(row), width,
// group (the cursor-sharing key), note}. Returns the element ([data-plot=title]) with
// `.cursor(k)`, which moves the slider's line and its read-out.
export function chart(o) {
  const box = h("div", null, { className: "chart" });
  box.dataset.plot = o.id || o.title;
  const vals = o.series.flatMap((s) => s.values).filter((y) => y !== null && Number.isFinite(y));
  box.append(h("p", `${o.title} (${o.yunit}${o.note ? `, ${o.note}` : ""}) against ${o.xname} (${o.xunit})`, { className: "chart-title" }));
  if (!vals.length) { box.append(h("p", "not defined over the sweep", { className: "muted" })); box.cursor = () => {}; return box; }
  const R = robustRange(vals);
  const colours = o.series.map((_, i) => SERIES_COLOURS[i % SERIES_COLOURS.length]);
  const readout = h("div", null, { className: "readout" });
  readout.dataset.readout = "";
  const atSlider = h("span"), atCursor = h("span", "hover the plot for the values at the cursor", { className: "muted" });
  readout.append(atSlider, h("br"), atCursor);
  let k = o.k, u = null;
  const xs = o.xs, xt = (x) => `${o.xname} = ${fmtValue(x)}${o.xunit === "°" ? "°" : ""}`;
  const valuesAt = (i) => o.series.map((s, n) => `${s.name} = ${fmtValue(s.values[i])}`).filter((_, n) => !u || u.series[n + 1].show).join(", ");
  const showSlider = () => { atSlider.textContent = `at the input slider, ${xt(xs[k])}: ${valuesAt(k)} ${o.yunit}`; readout.dataset.cursor = k; };
  const plugins = [{ hooks: {
    drawClear: [(p) => { // the working ranges, shaded under the curves
      const c = p.ctx, { left, top, width, height } = p.bbox; c.save(); c.fillStyle = "rgba(60, 140, 60, 0.08)";
      c.beginPath(); c.rect(left, top, width, height); c.clip();
      for (const [a, b] of o.ranges || []) for (const turn of o.xunit === "°" ? [-360, 0] : [0]) { // a range through 360° shaded at both ends
        const x0 = p.valToPos(a + turn, "x", true), x1 = p.valToPos(b + turn, "x", true);
        c.fillRect(x0, top, Math.max(1, x1 - x0), height);
      }
      c.restore();
    }],
    draw: [(p) => {
      const c = p.ctx, { top, height, left, width } = p.bbox; c.save();
      const [y0, y1] = [p.scales.y.min, p.scales.y.max];
      if (y0 < 0 && y1 > 0) { const y = p.valToPos(0, "y", true); c.strokeStyle = "#444"; c.lineWidth = 1; c.beginPath(); c.moveTo(left, y); c.lineTo(left + width, y); c.stroke(); }
      c.setLineDash([4, 3]); c.strokeStyle = "#a33";
      for (const m of o.marks || []) { const x = p.valToPos(m.x, "x", true); c.beginPath(); c.moveTo(x, top); c.lineTo(x, top + height); c.stroke(); }
      c.setLineDash([]); c.strokeStyle = "#e07000"; c.lineWidth = 2;
      const x = p.valToPos(xs[k], "x", true); c.beginPath(); c.moveTo(x, top); c.lineTo(x, top + height); c.stroke();
      c.restore();
    }],
    setCursor: [(p) => {
      const i = p.cursor.idx;
      if (i === null || i === undefined) return;
      atCursor.className = ""; atCursor.textContent = `at the cursor, ${xt(xs[i])}: ${valuesAt(i)} ${o.yunit}`;
    }],
    setSeries: [() => showSlider()],
  } }];
  const width = Math.max(240, o.width || 340);
  const opts = {
    width, height: 180, plugins,
    cursor: { sync: { key: o.group || "mechsyn", setSeries: false }, drag: { x: true, y: false, setScale: true }, points: { size: 6 } },
    scales: { x: { time: false }, y: { range: (p, lo, hi) => (R.clipped ? [R.lo, R.hi] : uPlot.rangeNum(hi - lo > 1e-12 * Math.max(1, Math.abs(hi)) ? lo : R.lo, hi - lo > 1e-12 * Math.max(1, Math.abs(hi)) ? hi : R.hi, 0.1, true)) } },
    axes: [{ grid: { stroke: "#e4e7ec", width: 1 }, ticks: { stroke: "#ccd" }, size: 30, font: "11px system-ui" },
      { grid: { stroke: "#e4e7ec", width: 1 }, ticks: { stroke: "#ccd" }, size: 52, font: "11px system-ui", values: (p, ticks) => ticks.map(fmtValue) }],
    legend: { live: false },
    series: [{ label: o.xname, value: (p, v) => fmtValue(v) }, ...o.series.map((s, i) => ({ label: s.name, stroke: colours[i], width: 1.6, spanGaps: false, value: (p, v) => fmtValue(v) }))],
  };
  const holder = h("div", null, { className: "chart-canvas", title: "drag across to zoom, double-click to zoom out; click to move the input there" });
  box.append(holder);
  u = new uPlot(opts, [xs, ...o.series.map((s) => s.values.map((v) => (v === null || !Number.isFinite(v) ? null : v)))], holder);
  box.uplot = u; box.marks = o.marks || []; // (for tests: the chart and its marked events)
  if (R.clipped) box.append(h("div", `clipped (spikes near a dead point): full range ${R.min.toPrecision(3)} … ${R.max.toPrecision(3)}; drag across to zoom`, { className: "muted clipped" }));
  if (R.clipped) box.lastChild.dataset.clipped = `${R.min} ${R.max}`;
  box.append(readout, statsTable(o.series, colours, o.yunit));
  const csv = h("button", "CSV", { title: "the plotted data as CSV" });
  csv.dataset.csv = "";
  csv.onclick = () => download(`${o.title.replace(/[^\w.-]+/g, "_")}.csv`, csvOf([{ name: `${o.xname} (${o.xunit})`, values: xs }, ...o.series.map((s) => ({ name: `${s.name} (${o.yunit})`, values: s.values }))]));
  const zoomOut = h("button", "Zoom out"); zoomOut.onclick = () => u.setScale("x", { min: xs[0], max: xs[xs.length - 1] });
  const tools = h("div", null, { className: "chart-tools" }); tools.append(csv, " ", zoomOut); box.append(tools);
  if (o.onPick) u.over.addEventListener("click", () => { if (u.select.width < 2 && u.cursor.idx !== null) o.onPick(u.cursor.idx); });
  box.cursor = (row) => { if (row === k || row === undefined) return; k = row; showSlider(); u.redraw(false, false); };
  showSlider();
  return box;
}

// The table of max, min, mean and RMS of every series (each name in its colour).
function statsTable(series, colours, unit) {
  const t = h("table", null, { className: "numtable stats" });
  const head = h("tr"); for (const c of ["", "max", "min", "mean", "RMS"]) head.append(h("th", c)); t.append(head);
  series.forEach((s, i) => {
    const st = stats(s.values), tr = h("tr");
    const name = h("td", s.name); name.style.color = colours[i]; name.style.fontWeight = "600";
    tr.append(name, ...["max", "min", "mean", "rms"].map((key) => h("td", st ? fmtValue(st[key]) : "–")));
    tr.dataset.series = s.name;
    t.append(tr);
  });
  t.title = `over the assembled rows, in ${unit}`;
  return t;
}

// An x/y plot of a point's path (equal scales) with the point at the slider's row, and its table.
export function pathPlot(name, path, xs, xname, k, cyclic = false) {
  const box = h("div", null, { className: "chart" });
  box.dataset.plot = `path of ${name}`;
  const pts = path.map((p, i) => [p, i]).filter(([p]) => p);
  box.append(h("p", `path of ${name}: y against x (equal scales, model units)`, { className: "chart-title" }));
  if (!pts.length) { box.cursor = () => {}; return box; }
  const X = pts.map(([p]) => p[0]), Y = pts.map(([p]) => p[1]);
  const [x0, x1, y0, y1] = [Math.min(...X), Math.max(...X), Math.min(...Y), Math.max(...Y)];
  const span = Math.max(x1 - x0, y1 - y0) || 1, W = 320, H = 220, pad = 28;
  const s = Math.min((W - 2 * pad) / (x1 - x0 || span), (H - 2 * pad) / (y1 - y0 || span));
  const sx = (x) => pad + (x - x0) * s, sy = (y) => H - pad - (y - y0) * s;
  const NS = "http://www.w3.org/2000/svg", svg = document.createElementNS(NS, "svg");
  svg.setAttribute("viewBox", `0 0 ${W} ${H}`); svg.setAttribute("class", "pathplot");
  const add = (tag, attrs, text) => { const e = document.createElementNS(NS, tag); for (const [a, v] of Object.entries(attrs)) e.setAttribute(a, v); if (text) e.textContent = text; svg.append(e); return e; };
  for (const [v, horiz] of [[x0, false], [x1, false], [y0, true], [y1, true]])
    add("text", horiz ? { x: 2, y: sy(v) + 4, class: "label" } : { x: sx(v) - 10, y: H - 6, class: "label" }, fmtValue(v));
  const d = pathD({ toScreen: (p) => [sx(p[0]), sy(p[1])] }, path, cyclic);
  add("rect", { x: pad, y: pad, width: W - 2 * pad, height: H - 2 * pad, class: "frame" });
  add("path", { d, class: "plotline", fill: "none", stroke: SERIES_COLOURS[0] });
  const dot = add("circle", { r: 4, fill: "#e07000" });
  const readout = h("div", null, { className: "readout" }); readout.dataset.readout = "";
  const place = (row) => {
    const p = path[row];
    if (p) { dot.setAttribute("cx", sx(p[0])); dot.setAttribute("cy", sy(p[1])); }
    readout.textContent = p ? `at the input slider, ${xname} = ${fmtValue(xs[row])}: x = ${fmtValue(p[0])}, y = ${fmtValue(p[1])}` : "not assembled here";
  };
  svg.addEventListener("mousemove", (ev) => {
    const r = svg.getBoundingClientRect(), px = ((ev.clientX - r.left) / r.width) * W, py = ((ev.clientY - r.top) / r.height) * H;
    let best = null, bd = Infinity;
    path.forEach((p, i) => { if (p) { const dd = (sx(p[0]) - px) ** 2 + (sy(p[1]) - py) ** 2; if (dd < bd) { bd = dd; best = i; } } });
    if (best !== null) readout.textContent = `nearest the cursor, ${xname} = ${fmtValue(xs[best])}: x = ${fmtValue(path[best][0])}, y = ${fmtValue(path[best][1])}`;
  });
  svg.addEventListener("mouseleave", () => place(k));
  box.append(svg, readout);
  const csv = h("button", "CSV", { title: "the path as CSV (input, x, y)" }); csv.dataset.csv = "";
  csv.onclick = () => download(`path_${name}.csv`, csvOf([{ name: xname, values: xs }, { name: `${name}_x`, values: path.map((p) => (p ? p[0] : null)) }, { name: `${name}_y`, values: path.map((p) => (p ? p[1] : null)) }]));
  const tools = h("div", null, { className: "chart-tools" }); tools.append(csv, ` ${pts.length} points; width ${fmtValue(x1 - x0)}, height ${fmtValue(y1 - y0)}`);
  box.append(tools);
  let k0 = k;
  box.cursor = (row) => { if (row === undefined || row === k0) return; k = k0 = row; place(row); };
  place(k);
  return box;
}


// The Plots tab of a planar file. `ctx`: {$, state, render, assembledNear}; returns renderPlots(),
// called on every repaint: the charts are made again only when the simulation, the quantity, the
// drive speed or the panel's width changed, else their slider lines move.
export function mountPlots({ $, state, render, assembledNear }) {
  let made = null, charts = [];
  const pick = (row) => { state.frame = assembledNear(row); render(); };
  function options(sim) {
    const m = state.mech, slides = sim.derived.slides || {};
    const groups = [["points", Object.keys(m.points || {}).filter((n) => sim.points[n]).map((n) => [`point:${n}`, `point ${n}`])],
      ["joints", m.joints.filter((j) => sim.points[j.id]).map(({ id: n }) => [`joint:${n}`, `joint ${n}${slides[n] ? " (slide)" : ""}`])],
      ["links", Object.keys(sim.links).map((n) => [`link:${n}`, `link ${n}`])],
      ["motion", Object.keys(sim.derived.transmission_angle || {}).length ? [["transmission", "transmission angle"]] : []]];
    return groups.filter(([, o]) => o.length);
  }
  function fillSelect(sel, sim) {
    const groups = options(sim), values = groups.flatMap(([, o]) => o.map(([v]) => v));
    if ([...sel.options].map((o) => o.value).join() === values.join()) return;
    const keep = sel.value;
    sel.replaceChildren(...groups.map(([label, o]) => { const g = h("optgroup", null, { label }); g.append(...o.map(([v, t]) => h("option", t, { value: v }))); return g; }));
    if (values.includes(keep)) sel.value = keep; else if (values.length) sel.value = values[0];
  }
  // [title, unit, series, note] of each chart of the quantity chosen, at drive speed w.
  function chartsOf(sim, what, w) {
    const [kind, name] = what.split(":"), rot = sim.input.type === "R";
    const at = `at ${sim.input.joint} = ${w} ${rot ? "rad/s" : "units/s"}`;
    const sc = (vals, f) => vals.map((v) => (v === null ? null : v * f));
    const comp = (arr, i, f) => arr.map((v) => (v ? v[i] * f : null)), norm = (arr, f) => arr.map((v) => (v ? Math.hypot(v[0], v[1]) * f : null));
    if (kind === "point") {
      const { position: pos, velocity: v, acceleration: a } = sim.points[name];
      return [[`velocity of ${name}`, "units/s", [{ name: "vx", values: comp(v, 0, w) }, { name: "vy", values: comp(v, 1, w) }, { name: "speed |v|", values: norm(v, w) }], at],
        [`acceleration of ${name}`, "units/s²", [{ name: "ax", values: comp(a, 0, w * w) }, { name: "ay", values: comp(a, 1, w * w) }, { name: "|a|", values: norm(a, w * w) }], at],
        [`position of ${name}`, "units", [{ name: "x", values: comp(pos, 0, 1) }, { name: "y", values: comp(pos, 1, 1) }]], ["path", name, pos]];
    }
    if (kind === "link") {
      const l = sim.links[name];
      return [[`angle of ${name}`, "°", [{ name: "θ", values: l.angle }], "counter-clockwise from +x"],
        [`angular velocity of ${name}`, "rad/s", [{ name: "ω", values: sc(l.angular_velocity, w) }], at],
        [`angular acceleration of ${name}`, "rad/s²", [{ name: "α", values: sc(l.angular_acceleration, w * w) }], at]];
    }
    if (kind === "joint" && (sim.derived.slides || {})[name]) {
      const s = sim.derived.slides[name];
      return [[`slide of ${name} along its guide`, "units", [{ name: "s", values: s.value }], `from the origin of ${s.guide}`],
        [`slide rate of ${name}`, "units/s", [{ name: "ṡ", values: sc(s.rate, w) }], at],
        [`slide acceleration of ${name}`, "units/s²", [{ name: "s̈", values: sc(s.acceleration, w * w) }], at]];
    }
    if (kind === "joint") { // a pin: the angle of its second link relative to its first
      const j = state.mech.joints.find((q) => q.id === name), L = (n) => sim.links[n];
      if (!j || j.links.length !== 2) return [];
      const [a, b] = j.links.map(L), diff = (key, f) => sim.input.values.map((_, i) => {
        const vb = b ? b[key][i] : 0, va = a ? a[key][i] : 0;
        return vb === null || va === null ? null : (vb - va) * f;
      });
      const rel = `${j.links[1]} relative to ${j.links[0]}`;
      return [[`angle of joint ${name}`, "°", [{ name: "φ", values: diff("angle", 1) }], rel],
        [`rate of joint ${name}`, "rad/s", [{ name: "φ̇", values: diff("angular_velocity", w) }], `${rel}, ${at}`],
        [`angular acceleration of joint ${name}`, "rad/s²", [{ name: "φ̈", values: diff("angular_acceleration", w * w) }], at]];
    }
    if (kind === "transmission")
      return [["transmission angle", "°", Object.entries(sim.derived.transmission_angle).map(([key, t]) => ({ name: `μ ${key}`, values: t.values })), "90° is best, under 40° poor"]];
    return [];
  }
  function renderPlots() {
    const sim = state.sim, sel = $("plot-what"), box = $("plots");
    if (!sim) { made = null; box.replaceChildren(h("p", "no simulation", { className: "muted" })); return; }
    if (!sim.rates) return; // an edit's first answer: the plots wait for the rates
    fillSelect(sel, sim);
    if (!$("tab-plots").classList.contains("on")) return;
    const w = Number($("drive-speed").value) || 1, width = box.clientWidth - 4;
    const key = [sel.value, w, width];
    if (made && made.sim === sim && made.key.join() === key.join()) { for (const c of charts) c.cursor(state.frame); return; }
    made = { sim, key };
    const xunit = sim.input.unit === "deg" ? "°" : "units", xname = sim.input.joint;
    const marks = sim.events.filter((e) => e.kind === "dead point" && e.input[xname] !== undefined).map((e) => ({ x: +e.input[xname], kind: e.kind, text: e.message }));
    charts = chartsOf(sim, sel.value || "", w).map(([title, unit, series, note]) => (title === "path"
      ? pathPlot(unit, series, sim.input.values, xname, state.frame, wholeTurn(sim))
      : chart({ title, xs: sim.input.values, xname, xunit, yunit: unit, series, note, k: state.frame, ranges: sim.working_ranges, marks, onPick: pick, width, group: "plots" })));
    box.replaceChildren(...charts);
  }
  return renderPlots;
}
