export function mountCentres() { return { notes: () => [] }; }
