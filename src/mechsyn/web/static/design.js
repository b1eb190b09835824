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
  return {
    linkElement: dims.linkElement,
    setLength: dims.setLength,
    // notes of the last design change, shown while its mechanism is the one drawn
    notes: () => [].concat(state.designNotes && state.designNotes.mech === state.mech ? state.designNotes.notes : [],
      robot.notes(), centres.notes()),
    burmester, robot, centres,
  };
}
