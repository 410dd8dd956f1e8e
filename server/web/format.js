// Numbers as a person writes them, shared by the views (and tested in node: tests/web/format.test.mjs).

/// A duration: "45 s", "3 min 20 s", "2 h 5 min"; "—" when there is none. The same forms as the
/// solver's figure titles (solver/core/AxisTicks.hpp, durationLabel).
export function humanDuration(seconds) {
  if (seconds === null || seconds === undefined || !Number.isFinite(seconds)) return '—';
  if (Math.abs(seconds) < 59.5) return `${Number(seconds.toPrecision(3))} s`;
  if (seconds < 3599.5) {
    const total = Math.round(seconds), m = Math.floor(total / 60), s = total % 60;
    return s ? `${m} min ${s} s` : `${m} min`;
  }
  const minutes = Math.round(seconds / 60), hours = Math.floor(minutes / 60), m = minutes % 60;
  return m ? `${hours} h ${m} min` : `${hours} h`;
}
