// Issue 40's designer tools, mounted by studio.js in one line: dimensions typed as design
// variables (dimensions.js), the Burmester choice of motion synthesis (burmester.js), every
// drive's own slider and the tool point driven by inverse kinematics (robot.js), the instant
// centres and a cam's profile (centres.js).
import { mountDimensions } from "./dimensions.js";
import { mountBurmester } from "./burmester.js";
import { mountRobot } from "./robot.js";
import { mountCentres } from "./centres.js";

// ctx: {$, root, state, render, setMech, rebase, setMode, showTab}
export function mountDesign(ctx) {
  const { state } = ctx;
  state.overlays = state.overlays || {};
  state.designNotes = null;
  const dims = mountDimensions(ctx);
  const burmester = mountBurmester(ctx);
  const robot = mountRobot(ctx);
  const centres = mountCentres(ctx);
  ctx.$("robot").append(robot.box);
  let shownSpatial = null;
  // the planar editing modes have no meaning in the 3-D view of a spatial file: hidden there
  function update() {
    const spatial = !!(state.mech && state.mech.kind !== "planar");
    if (spatial !== shownSpatial) { // only when it changes: a drag's repaint does no DOM work here
      shownSpatial = spatial;
      for (const b of ctx.root.querySelectorAll("#modes button")) b.hidden = spatial && b.dataset.mode !== "select";
      const fin = ctx.$("finish-link"); if (fin) fin.hidden = spatial;
    }
    robot.update(); centres.update();
  }
  return {
    update,
    linkElement: dims.linkElement,
    setLength: dims.setLength,
    guideRows: dims.guideRows,
    // notes of the last design change, shown while its mechanism is the one drawn
    notes: () => [].concat(state.designNotes && state.designNotes.mech === state.mech ? state.designNotes.notes : [],
      robot.notes(), centres.notes()),
    burmester, robot, centres,
  };
}
