// What the station page puts on `window` for benchmarks and tests (station.js).

interface Window {
  vahrMetrics?: import("../static/station.js").Metrics;
  vahrStation?: unknown;
}
