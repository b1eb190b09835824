// The player: play/pause, direction, speed and the input slider (kept to assembled inputs).

// `ctx`: {$, state, render, assembledNear}; returns setPlaying(on).
export function mountPlayer({ $, state, render, assembledNear }) {
  let timer = null, lastTick = 0;
  function tick(t) {
    if (!state.playing) return;
    const fps = +$("speed").value;
    if (t - lastTick >= 1000 / fps && state.sim) {
      lastTick = t;
      const n = state.sim.assembled.length, ok = state.sim.assembled;
      let next = state.frame + state.dir;
      const full = ok.every(Boolean);
      if (full) next = (next + n) % n;
      else if (next < 0 || next >= n || !ok[next]) { state.dir = -state.dir; next = state.frame + state.dir; if (next < 0 || next >= n || !ok[next]) next = state.frame; }
      state.frame = next;
      render();
    }
    timer = requestAnimationFrame(tick);
  }
  function setPlaying(on) {
    state.playing = on && !!state.sim;
    $("play").textContent = state.playing ? "❚❚" : "▶";
    cancelAnimationFrame(timer);
    if (state.playing) timer = requestAnimationFrame(tick);
  }
  $("play").onclick = () => setPlaying(!state.playing);
  $("direction").onclick = () => { state.dir = -state.dir; };
  $("input-slider").oninput = (ev) => { state.frame = assembledNear(+ev.target.value); render(); };
  // the arrow keys: one step of the input each (held down, the key repeats); a whole turn wraps
  setPlaying.step = (d) => {
    const s = $("input-slider"), max = +s.max, ok = state.sim ? state.sim.assembled : [];
    let v = +s.value + d;
    if (v > max || v < 0) v = ok.length && ok.every(Boolean) ? (v + max + 1) % (max + 1) : Math.min(max, Math.max(0, v));
    s.value = v;
    s.dispatchEvent(new Event("input"));
  };
  return setPlaying;
}
