export function mountBurmester() { return { notes: () => [] }; }
