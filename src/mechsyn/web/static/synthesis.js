// The Synthesis tab: a run started on the server, followed live (server-sent events, or polled in
// a notebook), its results listed best first with their quality, previewed on hover, applied.
import { call, eventsUrl, transport } from "./api.js";
import { h } from "./numeric.js";

// `ctx`: {$, state, render, setMech, setMode, design}; returns {renderPoses} (called when a target is added).
export function mountSynthesis({ $, state, render, setMech, setMode = () => {}, design = null }) {
  let source = null, job = null;
  $("clear-targets").onclick = () => { state.targets = []; state.targetAngles = []; state.preview = null; state.previewResult = null; state.motionCurves = null; $("target-count").textContent = 0; renderPoses(); render(); };

  // Motion through poses: each clicked target is a pose of the guided body, its angle typed here
  // (degrees, counter-clockwise from x) and drawn as a tick on the canvas.
  const poseAngles = () => state.targets.map((_, i) => (state.targetAngles || [])[i] || 0);
  function renderPoses() {
    const on = $("synth-kind").value === "motion";
    state.showPoses = on;
    $("synth-size").hidden = !["", "fourbar_path"].includes($("synth-kind").value); // the path run's size bound
    if (!on) { $("synth-poses").replaceChildren(); return; }
    const t = h("table", null, { className: "numtable" });
    t.dataset.table = "poses";
    const head = h("tr"); for (const c of ["pose", "x", "y", "angle °"]) head.append(h("th", c)); t.append(head);
    state.targets.forEach((p, i) => {
      const a = h("input", null, { value: String(poseAngles()[i]), size: 5 });
      a.dataset.pose = i;
      a.onchange = () => { const v = Number(a.value); if (!Number.isFinite(v)) return; state.targetAngles = poseAngles(); state.targetAngles[i] = v; render(); };
      const td = h("td"); td.append(a);
      // a pose's x and y typed (issue 40)
      const xy = [0, 1].map((k) => {
        const c = h("input", null, { value: String(p[k]), size: 6 });
        c.dataset.poseXy = i; c.dataset.coord = "xy"[k];
        c.onchange = () => { const v = Number(c.value); if (!Number.isFinite(v)) return; state.targets[i] = state.targets[i].slice(); state.targets[i][k] = v; render(); };
        const cell = h("td"); cell.append(c); return cell;
      });
      const tr = h("tr"); tr.append(h("td", `T${i + 1}`), ...xy, td);
      t.append(tr);
    });
    $("synth-poses").replaceChildren(h("p", "Click 3 to 5 poses (Targets), then type each pose's angle.", { className: "muted" }), t);
  }
  $("synth-kind").addEventListener("change", () => { renderPoses(); render(); });
  $("synth-run").onclick = async () => {
    $("synth-status").textContent = "";
    try {
      const kind = $("synth-kind").value || "fourbar_path";
      job = await call(`/api/synth/${kind}`, { targets: state.targets, time_limit: +$("synth-time").value,
        ...(kind === "motion" ? { angles: poseAngles() } : {}),
        ...(kind === "fourbar_path" ? { max_size: $("synth-max-size").value === "" ? NaN : +$("synth-max-size").value } : {}) });
    } catch (e) { $("synth-status").textContent = `${e.error}${e.hint ? " — fix: " + e.hint : ""}`; return; }
    $("synth-run").disabled = true; $("synth-cancel").disabled = false;
    $("synth-results").replaceChildren(); $("synth-notes").replaceChildren();
    const show = (snap) => {
      const p = snap.progress, of = p.total || 1; // mechsyn.progress.Progress's to_dict
      $("synth-progress").max = of; $("synth-progress").value = snap.state === "running" ? p.done : of;
      const words = [p.stage, p.message].filter((w) => w && w !== snap.state).join(": "), stage = words ? ` (${words})` : "";
      $("synth-status").textContent = `${snap.state}${stage}: ${p.done}${p.total ? "/" + p.total : ""}, best so far ${p.best === null ? "–" : p.best.toPrecision(4)}, ${snap.seconds} s`;
    };
    const end = (snap) => {
      show(snap);
      $("synth-run").disabled = false; $("synth-cancel").disabled = true;
      if (snap.error) $("synth-status").textContent = `failed: ${snap.error.message}`;
      if (snap.result) {
        const rs = snap.result.results, errs = rs.map((r) => r.error).filter(Number.isFinite);
        // the status line tells what the list shows: its best error, not the search's internal one
        $("synth-status").textContent = `${snap.state}: ${rs.length} result${rs.length === 1 ? "" : "s"}` +
          (errs.length ? `, best error ${Math.min(...errs).toPrecision(4)}` : "") + ` in ${snap.seconds} s`;
        state.motionCurves = snap.result.curves || null;
        showResults(rs);
        $("synth-notes").replaceChildren(...(snap.result.notes || []).map((n) => h("li", n)));
      }
    };
    if (transport.events) {
      source = new EventSource(eventsUrl(job.id));
      source.addEventListener("progress", (e) => show(JSON.parse(e.data)));
      source.addEventListener("end", (e) => { source.close(); end(JSON.parse(e.data)); });
      source.onerror = () => { if (source.readyState === 2) { $("synth-run").disabled = false; $("synth-cancel").disabled = true; } };
    } else { // no event stream (notebook widget): poll the job
      const poll = async () => { const snap = await call(`/api/jobs/${job.id}`); if (snap.state === "running") { show(snap); setTimeout(poll, 300); } else end(snap); };
      poll();
    }
  };
  $("synth-cancel").onclick = async () => { if (job) await call(`/api/jobs/${job.id}/cancel`, {}); };

  function showResults(results) {
    const items = results.map((r, i) => {
      const li = h("li");
      li.dataset.result = i;
      li.append(`${r.label} `);
      const q = r.quality || (r.candidate && r.candidate.quality);
      if (q && q.link_ratio !== undefined) li.append(h("span", ` size ${(+q.size).toPrecision(3)} (${(+q.size_ratio).toFixed(1)}× the target), links ${(+q.link_ratio).toFixed(1)}:1, min μ ${(+q.min_transmission_angle).toFixed(0)}°${q.full_turn ? ", full turn" : ""} `, { className: "quality" }));
      if (r.mechanism) {
        const b = h("button", "Apply"); b.dataset.apply = i;
        b.onclick = () => { state.preview = null; state.previewResult = null; state.fileName = ""; setMech(r.mechanism, { fit: true }); setMode("select"); };
        li.append(b);
      }
      // the report's reason (synth path's): why it is infeasible, or the bound that decides it and how to lift it
      if (r.reason) { const why = h("div", r.reason, { className: "reason" }); why.dataset.reason = i; li.append(why); }
      // hover: the candidate's whole curve (and, for motion, its pivots) over the targets
      li.onmouseenter = () => { state.preview = r.curve || r.path; state.previewResult = r; render(); if (design) design.burmester.renderBox(); };
      return li;
    });
    $("synth-results").replaceChildren(...items);
    if (results.length) { state.preview = results[0].curve || results[0].path; state.previewResult = results[0]; render(); }
    if (design) design.burmester.renderBox();
  }
  return { renderPoses };
}
