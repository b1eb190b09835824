// The Analysis tab: the result first (mobility and what it means, Grashof's class, the motion:
// working range, every slider's stroke and extreme positions, every rocker's range, the time
// ratio, transmission angles, dead points), then the Assur groups; the specialist notes (every
// mobility formula with its numbers, the rank method's lines, the structure notes) folded.
import { GROUP_COLOURS } from "./draw.js";
import { h } from "./numeric.js";

// The structure report's formulas by the names of the literature; the spatial ones are marked
// when read for a planar file.
const FORMULA_NAMES = { chebyshev: "Chebyshev", grubler: "Grübler", malyshev: "Malyshev", somov_malyshev: "Somov–Malyshev",
  gokhman_contours: "Gokhman (contours)", scheme_check: "scheme check", ozol_redundant: "Ozol (redundant constraints)",
  redundant_from_mobility: "redundant constraints from the mobility" };
const SPATIAL_FORMULAS = new Set(["malyshev", "somov_malyshev"]);

const n3 = (v) => String(+(+v).toPrecision(4));
const deg = (v) => `${(+v).toFixed(1)}°`;

// A working range [a, b] of an R input in words: one range through 360° is written so
// ("243.4° … 116.6° through 360°"), never as two.
export function rangeText([a, b], rot) {
  if (!rot) return `${n3(a)} … ${n3(b)}`;
  if (b - a >= 360 - 1e-9) return "full turn (360°)";
  const a0 = ((a % 360) + 360) % 360, b0 = a0 + (b - a);
  return b0 >= 360 ? `${deg(a0)} … ${deg(b0 - 360)} through 360° (${deg(b - a)} wide)` : `${deg(a0)} … ${deg(b0)}`;
}

// The motion summary of the simulation (the library's `motion_summary`, as `mechsyn simulate`).
function summaryLines(sim) {
  const s = sim.derived.motion, out = [], rot = sim.input.type === "R", x = (v) => (rot ? deg(((v % 360) + 360) % 360) : n3(v)), J = sim.input.joint;
  if (!s) return out;
  const ratio = (t) => (t ? `; time ratio ${n3(t.ratio)} (working stroke ${deg(t.forward)} of the crank, return ${deg(t.return)})` : "");
  for (const [j, sl] of Object.entries(s.sliders || {})) {
    const at = (e) => (e.point ? `(${n3(e.point[0])}, ${n3(e.point[1])})` : `slide ${n3(e.slide)}`) + ` at ${J} = ${x(e.input)}`;
    const p = h("p", null, { className: "result-line" });
    p.dataset.stroke = j;
    p.append(h("b", `slider ${j}: stroke ${n3(sl.stroke)}`), ` — extreme positions ${at(sl.min)} and ${at(sl.max)}${ratio(sl.time_ratio)}`);
    out.push(p);
  }
  for (const [link, r] of Object.entries(s.rockers || {})) {
    const p = h("p", null, { className: "result-line" });
    p.dataset.rocker = link;
    if (r.full_turn) p.append(h("b", `${link}`), ` (pivot ${r.pivot}) turns fully`);
    else p.append(h("b", `${link}: swings ${deg(r.range)}`), ` (pivot ${r.pivot}) between ${deg(r.min.angle)} at ${J} = ${x(r.min.input)} and ${deg(r.max.angle)} at ${J} = ${x(r.max.input)}${ratio(r.time_ratio)}`);
    out.push(p);
  }
  return out;
}

function motion(sim) {
  const out = [h("h3", "Motion")], rot = sim.input.type === "R";
  const full = rot && sim.assembled.every(Boolean);
  out.push(h("p", `working range of ${sim.input.joint}: ` + (full ? "full turn (360°)" : sim.working_ranges.map((r) => rangeText(r, rot)).join(", ") || "none")));
  out.push(...summaryLines(sim));
  for (const [key, t] of Object.entries(sim.derived.transmission_angle || {}))
    if (t.min !== null) out.push(h("p", `transmission angle ${key}: ${t.min.toFixed(1)}° … ${t.max.toFixed(1)}°`));
  const dead = sim.events.filter((e) => e.kind === "dead point");
  for (const e of dead) out.push(h("p", `dead point at ${Object.entries(e.input).map(([j, v]) => `${j} = ${(+v).toFixed(2)}`).join(", ")}: ${e.message}`, { className: "muted" }));
  return out;
}

// The mobility in a designer's words: how many drives it needs.
function mobilityHead(st) {
  const W = st.mobility;
  const says = W >= 1 ? `moves with ${W} drive${W > 1 ? "s" : ""}` : W === 0 ? "cannot move: a structure" : `cannot move: a structure with ${-W} redundant constraint${W < -1 ? "s" : ""}`;
  return h("h3", `Mobility W = ${W}: ${says}` + (st.mobility_source ? ` (${st.mobility_source})` : " (formulas)"));
}

function specialist(a, planar) {
  const out = [];
  const st = a.structure;
  if (st) {
    const t = h("table");
    for (const [name, f] of Object.entries(st.formulas)) {
      const tr = h("tr");
      let title = FORMULA_NAMES[name] || name.replace(/_/g, " ");
      if (planar && SPATIAL_FORMULAS.has(name)) title += " (spatial formula)"; // 6 freedoms per contour
      tr.append(h("td", title), h("td", f.expression, { className: "formula" }));
      t.append(tr);
    }
    out.push(h("h3", "Mobility formulas"), t);
    for (const n of st.notes || []) out.push(h("p", n, { className: "muted" }));
  }
  if (a.rank_summary) { out.push(h("h3", "Rank method (exact)")); for (const l of a.rank_summary) out.push(h("p", l, { className: "formula" })); }
  else if (a.rank_unavailable) out.push(h("p", `rank method: ${a.rank_unavailable}`, { className: "muted" }));
  if (!out.length) return [];
  const d = h("details", null, { className: "specialist" });
  d.append(h("summary", "Specialist notes: every mobility formula with its numbers, the rank method"), ...out);
  return [d];
}

// The tab's content for the analysis `a` (the server's /api/analyze), the simulation `sim`, the
// editor's `errors` and the mechanism `mech`.
export function analysisTab({ a, sim, errors, mech, diagnostics = [] }) {
  const out = [], planar = !!(mech && mech.kind === "planar");
  if (errors.length) out.push(h("p", `Input problem: ${errors[0].message}`, { className: "err" }));
  const blocking = diagnostics.filter((d) => d.blocks);
  // a build in progress (a pivot not joined yet, a loose link): the next step, not the file's error
  if (a && a.error && blocking.length) { out.push(h("p", "Nothing to analyse yet:", { className: "muted" }), ...blocking.map((d) => h("p", d.message, { className: "muted" }))); return out; }
  if (a && a.error) out.push(h("p", `${a.error}${a.hint ? " — fix: " + a.hint : ""}`, { className: "muted" }));
  if (a && a.structure) {
    out.push(mobilityHead(a.structure));
    const f = a.structure.formulas || {}, main = f.chebyshev || f.grubler;
    if (main) out.push(h("p", `${f.chebyshev ? "Chebyshev–Grübler" : "Grübler"}: ${main.expression}`, { className: "formula" }));
  }
  const gr = planar ? (sim && sim.derived.grashof) || (a && a.grashof) : null;
  if (gr) { out.push(h("h3", `Grashof: ${gr.classification}`)); out.push(h("p", gr.expression, { className: "formula" })); }
  if (sim) out.push(...motion(sim));
  if (a && a.assur) {
    out.push(h("h3", `Assur groups: class ${a.assur.mechanism_class_roman}`));
    out.push(h("p", a.assur.structural_formula, { className: "formula" }));
    const ul = h("ul");
    [...a.assur.initial_mechanisms, ...a.assur.groups].forEach((g, i) => {
      const li = h("li");
      li.append(h("span", "", { className: `swatch g${i % GROUP_COLOURS.length}` }), `${g.label} (class ${g.class_roman}, order ${g.order})`);
      ul.append(li);
    });
    out.push(ul);
  } else if (a && a.assur_unavailable) {
    const moves = a.structure && a.structure.mobility >= 1 && /structure, not a mechanism/.test(a.assur_unavailable);
    out.push(h("p", moves ? `Assur groups: none by Chebyshev's count (${a.assur_unavailable.split(":")[0]}, which reads it as a structure); `
      + `it moves (W = ${a.structure.mobility} by the rank method) because its dimensions are special: a link repeats a constraint (the banner names it)`
      : `Assur groups: ${a.assur_unavailable}`, { className: "muted" }));
  }
  if (a) out.push(...specialist(a, planar));
  if (!out.length) out.push(h("p", "Analysis of the drawn mechanism appears here.", { className: "muted" }));
  return out;
}
