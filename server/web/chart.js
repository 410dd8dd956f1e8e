// Coverage histograms drawn as SVG in the page: one or more jobs' distributions overlaid, each with its
// ensemble band where the job has one. Axes tick at round numbers (1-2-5 steps), as the server's own
// figures do (solver/core/AxisTicks.hpp).

const SVG = 'http://www.w3.org/2000/svg';

/// 1, 2 or 5 times a power of ten, the one nearest to `raw` (> 0) on a log scale.
export function niceStep(raw) {
  if (!(raw > 0) || !Number.isFinite(raw)) return 1;
  const p = 10 ** Math.floor(Math.log10(raw));
  const f = raw / p;
  return (f < 1.5 ? 1 : f < 3.5 ? 2 : f < 7.5 ? 5 : 10) * p;
}

/// Every multiple of the step for about `intervals` intervals inside [lo, hi].
export function niceTicks(lo, hi, intervals = 5) {
  if (!(hi > lo)) return [];
  const step = niceStep((hi - lo) / Math.max(1, intervals));
  const slack = 1e-6;
  const ticks = [];
  for (let k = Math.ceil(lo / step - slack); k <= Math.floor(hi / step + slack); k++) {
    const v = k * step;
    ticks.push(Math.abs(v) < slack * step ? 0 : v);
  }
  return ticks;
}

/// A tick label with the decimals its step needs: 0.05, 0.1, 0.15.
export function tickLabel(value, step) {
  const decimals = step > 0 ? Math.max(0, -Math.floor(Math.log10(step) + 1e-9)) : 0;
  if (step > 0 && (step < 1e-4 || step >= 1e6)) return value.toPrecision(3);
  return String(Number(value.toFixed(decimals)));
}

function el(name, attrs = {}, text) {
  const node = document.createElementNS(SVG, name);
  for (const [k, v] of Object.entries(attrs)) node.setAttribute(k, String(v));
  if (text !== undefined) node.textContent = text;
  return node;
}

export const SERIES_COLOURS = ['#2b59c3', '#d1495b', '#2e8b57', '#8a5a00'];

/// An SVG histogram chart of `series` ([{label, edges, counts, band?: {low, high, mean}}]): the fraction
/// of particles per coverage bin, bars for a single series and outlined steps when several overlay;
/// a band is the 95 % interval of the ensemble mean per bin. Returns the <svg> element.
export function coverageChart(series, { title = 'Coverage distribution', width = 640, height = 360 } = {}) {
  const margin = { left: 60, right: 16, top: 34, bottom: 46 };
  const plotW = width - margin.left - margin.right, plotH = height - margin.top - margin.bottom;
  const normalised = series.map((s) => {
    const total = s.counts.reduce((a, b) => a + b, 0) || 1;
    const bandTotal = s.band ? s.band.mean.reduce((a, b) => a + b, 0) || 1 : 1;
    return {
      ...s,
      fractions: s.counts.map((c) => c / total),
      band: s.band && { low: s.band.low.map((v) => Math.max(0, v) / bandTotal), high: s.band.high.map((v) => v / bandTotal) },
    };
  });
  let top = 0;
  for (const s of normalised) {
    top = Math.max(top, ...s.fractions);
    if (s.band) top = Math.max(top, ...s.band.high);
  }
  top = top > 0 ? top * 1.1 : 1;
  const xLo = Math.min(...series.map((s) => s.edges[0])), xHi = Math.max(...series.map((s) => s.edges[s.edges.length - 1]));
  const px = (x) => margin.left + ((x - xLo) / (xHi - xLo)) * plotW;
  const py = (y) => margin.top + plotH - (y / top) * plotH;

  const svg = el('svg', { viewBox: `0 0 ${width} ${height}`, class: 'chart', role: 'img' });
  const description = series.map((s) => s.label).join(' and ');
  svg.setAttribute('aria-label', `${title}: ${description}`);
  svg.append(el('title', {}, `${title}: ${description}`));
  svg.append(el('rect', { x: 0, y: 0, width, height, fill: '#fff' }));
  svg.append(el('text', { x: width / 2, y: 20, 'text-anchor': 'middle', 'font-size': 14, class: 'chart-title' }, title));

  normalised.forEach((s, i) => {
    const colour = SERIES_COLOURS[i % SERIES_COLOURS.length];
    const group = el('g', { class: 'series', 'data-label': s.label });
    if (s.band) {
      for (let b = 0; b < s.band.low.length; b++) {
        const y0 = py(s.band.high[b]), y1 = py(s.band.low[b]);
        group.append(el('rect', { x: px(s.edges[b]), y: y0, width: Math.max(0, px(s.edges[b + 1]) - px(s.edges[b])),
          height: Math.max(0, y1 - y0), fill: colour, 'fill-opacity': 0.22, class: 'band' }));
      }
    }
    if (normalised.length === 1) {
      s.fractions.forEach((f, b) => {
        group.append(el('rect', { x: px(s.edges[b]), y: py(f), width: Math.max(0, px(s.edges[b + 1]) - px(s.edges[b]) - 0.5),
          height: Math.max(0, py(0) - py(f)), fill: colour, 'fill-opacity': 0.8, class: 'bar' }));
      });
    } else {
      let d = `M${px(s.edges[0])},${py(0)}`;
      s.fractions.forEach((f, b) => { d += ` L${px(s.edges[b])},${py(f)} L${px(s.edges[b + 1])},${py(f)}`; });
      d += ` L${px(s.edges[s.edges.length - 1])},${py(0)}`;
      group.append(el('path', { d, fill: colour, 'fill-opacity': 0.12, stroke: colour, 'stroke-width': 2, class: 'steps' }));
    }
    svg.append(group);
  });

  const axes = el('g', { class: 'axes', 'font-size': 11 });
  axes.append(el('rect', { x: margin.left, y: margin.top, width: plotW, height: plotH, fill: 'none', stroke: '#000' }));
  const xs = niceTicks(xLo, xHi, 10), ys = niceTicks(0, top, 5);
  const xStep = xs.length > 1 ? xs[1] - xs[0] : 0, yStep = ys.length > 1 ? ys[1] - ys[0] : 0;
  for (const x of xs) {
    axes.append(el('line', { x1: px(x), y1: py(0), x2: px(x), y2: py(0) + 5, stroke: '#000' }));
    axes.append(el('text', { x: px(x), y: py(0) + 18, 'text-anchor': 'middle', class: 'tick-x' }, tickLabel(x, xStep)));
  }
  for (const y of ys) {
    axes.append(el('line', { x1: margin.left - 5, y1: py(y), x2: margin.left, y2: py(y), stroke: '#000' }));
    axes.append(el('text', { x: margin.left - 8, y: py(y) + 4, 'text-anchor': 'end', class: 'tick-y' }, tickLabel(y, yStep)));
  }
  axes.append(el('text', { x: margin.left + plotW / 2, y: height - 8, 'text-anchor': 'middle', 'font-size': 12 },
    'surface coverage φ [-]'));
  axes.append(el('text', { x: 14, y: margin.top + plotH / 2, 'text-anchor': 'middle', 'font-size': 12,
    transform: `rotate(-90 14 ${margin.top + plotH / 2})` }, 'fraction of particles [-]'));
  svg.append(axes);
  return svg;
}
