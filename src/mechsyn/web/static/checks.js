// Checks of the edited mechanism decided by the drawing alone (run on every drag step, no server),
// and the key that says when the server's checks (mobility, drives, connections) must run again.
import { linkName, membership } from "./draw.js";

// What the server's check depends on besides the joints' places: the links, joints, types, drives.
// A spatial file's check also reads its geometry (whether it can move at all: a Bennett linkage
// whose special geometry an edit broke is rigid), so there the points and axes count too.
export function topologyKey(m) {
  const geometry = (j) => (m.kind === "planar" ? [] : [j.point, j.axis, j.axis2]);
  return JSON.stringify([m.kind, m.ground, m.links.map(linkName),
    m.joints.map((j) => [j.id, j.type, j.links, !!j.actuated, ...geometry(j)])]);
}

// Everything the server's check reads: the topology and every joint as written, its place too,
// planar files included (their mobility is the rank method's, read from the joints' places: a
// four-bar drawn along one line has W = 2, the same four-bar drawn open W = 1), and the names of
// the points' links (a point on a missing link is refused). Not the points' places, the masses or
// the loads (the check does not read them).
export function checkKey(m) {
  return JSON.stringify([m.kind, m.ground, m.links.map(linkName), m.joints,
    Object.entries(m.points || {}).map(([n, p]) => [n, p.link])]);
}

// The mechanism's length scale: the diagonal of its joints' bounding box (1 for fewer than two).
export function lengthScale(m) {
  const pts = m.joints.map((j) => j.point).filter(Boolean);
  if (pts.length < 2) return 1;
  const xs = pts.map((p) => p[0]), ys = pts.map((p) => p[1]);
  return Math.hypot(Math.max(...xs) - Math.min(...xs), Math.max(...ys) - Math.min(...ys)) || 1;
}

// A bar (a link with two R joints) whose joints lie on top of each other has no length: the
// motion drawn would be nonsense. Joints of a plate may coincide (a multiple joint drawn as two)
// and a slider's R and P joints do. Tolerance: 1e-3 of the length scale.
export function geometryChecks(m) {
  const out = [], tol = 1e-3 * lengthScale(m), byId = Object.fromEntries(m.joints.map((j) => [j.id, j]));
  for (const [name, g] of Object.entries(membership(m))) {
    if (name === m.ground || g.joints.length !== 2) continue;
    const [a, b] = g.joints.map((id) => byId[id]);
    if (a.type !== "R" || b.type !== "R") continue;
    const d = Math.hypot(a.point[0] - b.point[0], a.point[1] - b.point[1]);
    if (d < tol) out.push({ level: "error", blocks: false, short: "joints on top of each other",
      message: `joints ${a.id} and ${b.id} lie on top of each other: link ${name} has no length (${d.toPrecision(2)}). Drag one of them away`,
      elements: [{ kind: "link", id: name }, { kind: "joint", id: a.id }, { kind: "joint", id: b.id }] });
  }
  return out;
}

// Coordinates as a person would type them: rounded to about a tenth of a pixel at scale s (px per unit).
export function tidy(c, s) {
  const digits = Math.max(0, Math.ceil(Math.log10(Math.max(s, 1e-9))) + 1);
  return +(+c).toFixed(Math.min(digits, 12));
}
