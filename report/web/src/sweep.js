// A sweep folder's page: the plan (axes, cells done / failed / missing) and each metric against
// each numeric axis, drawn from the aggregate's data: the mean over the other axes at each of the
// axis's values (sampled axes: bins) with its 95 % confidence band (docs/sweeps.md).

const kSvg = 'http://www.w3.org/2000/svg';

function element(tag, attributes = {}, children = []) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  for (const child of children) node.append(child);
  return node;
}

function svgElement(tag, attributes = {}, text = undefined) {
  const node = document.createElementNS(kSvg, tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, String(value));
  if (text !== undefined) node.textContent = text;
  return node;
}

// A number as a short label (4 significant digits, no trailing zeros).
export function shortNumber(value) {
  if (value === null || value === undefined || !Number.isFinite(value)) return '';
  if (value !== 0 && (Math.abs(value) >= 1e5 || Math.abs(value) < 1e-3)) return value.toExponential(2);
  return String(Number(value.toPrecision(4)));
}

// About `count` round tick values covering [lo, hi].
function niceTicks(lo, hi, count = 5) {
  if (!(hi > lo)) return [lo];
  const raw = (hi - lo) / count;
  const power = 10 ** Math.floor(Math.log10(raw));
  const step = [1, 2, 2.5, 5, 10].map((m) => m * power).find((s) => s >= raw);
  const ticks = [];
  for (let v = Math.ceil(lo / step) * step; v <= hi + step * 1e-9; v += step) ticks.push(v);
  return ticks;
}

export function sweepPlanSection(sweep) {
  const node = element('section', { class: 'sweep-plan' }, [element('h2', {}, ['Plan'])]);
  if (sweep.description) node.append(element('p', { class: 'note' }, [sweep.description]));
  const state = element('p', { class: 'cells' });
  state.append(`mmh ${sweep.command}: ${sweep.cells} cells (${sweep.points} parameter settings x ` +
    `${sweep.replicates} replicates): `);
  for (const [key, label] of [['done', 'done'], ['failed', 'failed'], ['missing', 'missing']]) {
    state.append(element('span', { class: `cell-state ${key}`, 'data-state': key },
      [`${sweep[key]} ${label}`]), ' ');
  }
  node.append(state);
  if (!sweep.aggregate_current) {
    node.append(element('p', { class: 'error stale' }, [
      'The aggregate tables differ from what the cells hold now (cells finished or were rerun ' +
      'after it was written): run mmh sweep aggregate again. The page shows the files.']));
  }
  return node;
}

// One metric against one axis: mean line, 95 % CI band, a point per value with its numbers.
export function linePlot(plot) {
  const width = 440, height = 290;
  const margin = { left: 64, right: 14, top: 26, bottom: 46 };
  const svg = svgElement('svg', {
    width, height, viewBox: `0 0 ${width} ${height}`, class: 'sweep-plot',
    'data-metric': plot.metric, 'data-axis': plot.axis,
  });
  const points = plot.points.map(([x, y, lo, hi]) => ({ x, y, lo, hi }));
  const fx = (x) => (plot.log_x ? Math.log10(x) : x);
  const xs = points.map((p) => fx(p.x));
  const ys = points.flatMap((p) => [p.y, p.lo, p.hi]).filter((v) => v !== null && Number.isFinite(v));
  let [x0, x1] = [Math.min(...xs), Math.max(...xs)];
  let [y0, y1] = [Math.min(...ys), Math.max(...ys)];
  if (x1 === x0) { x0 -= 1; x1 += 1; }
  if (y1 === y0) { y0 -= Math.abs(y0) * 0.1 + 1; y1 += Math.abs(y1) * 0.1 + 1; }
  const pad = 0.05 * (y1 - y0);
  y0 -= pad; y1 += pad;
  const px = (x) => margin.left + ((fx(x) - x0) / (x1 - x0)) * (width - margin.left - margin.right);
  const py = (y) => height - margin.bottom - ((y - y0) / (y1 - y0)) * (height - margin.top - margin.bottom);
  svg.append(svgElement('text', { x: width / 2, y: 16, 'text-anchor': 'middle', class: 'title' },
    `${plot.metric} against ${plot.axis}`));
  // Axes, ticks and labels.
  const axis = svgElement('g', { class: 'axis' });
  axis.append(svgElement('line', { x1: margin.left, x2: width - margin.right, y1: height - margin.bottom, y2: height - margin.bottom }));
  axis.append(svgElement('line', { x1: margin.left, x2: margin.left, y1: margin.top, y2: height - margin.bottom }));
  for (const p of points) {
    axis.append(svgElement('text', { x: px(p.x), y: height - margin.bottom + 14, 'text-anchor': 'middle' }, shortNumber(p.x)));
  }
  for (const v of niceTicks(y0, y1)) {
    axis.append(svgElement('line', { x1: margin.left - 4, x2: margin.left, y1: py(v), y2: py(v) }));
    axis.append(svgElement('text', { x: margin.left - 6, y: py(v) + 4, 'text-anchor': 'end' }, shortNumber(v)));
  }
  axis.append(svgElement('text', { x: (margin.left + width - margin.right) / 2, y: height - 10, 'text-anchor': 'middle' },
    plot.axis + (plot.log_x ? ' (log)' : '')));
  axis.append(svgElement('text', { x: 14, y: (margin.top + height - margin.bottom) / 2, 'text-anchor': 'middle',
    transform: `rotate(-90 14 ${(margin.top + height - margin.bottom) / 2})` }, plot.metric));
  svg.append(axis);
  // The CI band where the groups have one (n >= 2).
  const banded = points.filter((p) => p.lo !== null && p.hi !== null);
  if (banded.length >= 2) {
    const upper = banded.map((p) => `${px(p.x)},${py(p.hi)}`);
    const lower = banded.slice().reverse().map((p) => `${px(p.x)},${py(p.lo)}`);
    svg.append(svgElement('polygon', { points: upper.concat(lower).join(' '), class: 'band' }));
  }
  svg.append(svgElement('polyline', { points: points.map((p) => `${px(p.x)},${py(p.y)}`).join(' '), class: 'mean' }));
  for (const p of points) {
    const dot = svgElement('circle', {
      cx: px(p.x), cy: py(p.y), r: 3.5, class: 'point',
      'data-x': p.x, 'data-y': p.y, 'data-lo': p.lo ?? '', 'data-hi': p.hi ?? '',
    });
    dot.append(svgElement('title', {}, `${plot.axis} = ${shortNumber(p.x)}: mean ${p.y}` +
      (p.lo !== null ? `, 95 % CI ${p.lo} .. ${p.hi}` : '')));
    svg.append(dot);
  }
  return svg;
}

export function sweepPlotsSection(plots) {
  const node = element('section', {}, [element('h2', {}, ['Metrics against the axes'])]);
  node.append(element('p', { class: 'note' }, [
    'Each metric against each numeric axis: the mean over the other axes at each value (sampled ' +
    'axes: 5 bins of equal count) with its 95 % confidence interval (Student\'s t; shaded), ' +
    'from results.csv as plots/<metric>_vs_<axis>.svg draws them. Hover a point for its numbers.']));
  const grid = element('div', { class: 'plots' });
  for (const plot of plots) grid.append(linePlot(plot));
  node.append(grid);
  return node;
}

// For the browser test: the plots' points as drawn (from the DOM).
export function drawnPlots() {
  return [...document.querySelectorAll('svg.sweep-plot')].map((svg) => ({
    metric: svg.dataset.metric,
    axis: svg.dataset.axis,
    band: !!svg.querySelector('polygon.band'),
    points: [...svg.querySelectorAll('circle.point')].map((c) => ['x', 'y', 'lo', 'hi'].map(
      (k) => (c.dataset[k] === '' ? null : Number(c.dataset[k])))),
  }));
}
