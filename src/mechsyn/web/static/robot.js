export function mountRobot() { return { notes: () => [] }; }
