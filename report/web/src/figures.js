// The report's 2D figures: annotation timelines (the paper's Figure 3 colours), chosen segments,
// transitions and spatial markers on the timelines, DTW cost images with the optimal and linear
// warps (Figure 4), tables, and the study's SVG figures.

// Categorical colours of the takes (Okabe-Ito, distinguishable with colour-vision deficiency).
export const takeColors = ['#0072B2', '#E69F00', '#009E73', '#CC79A7', '#56B4E9', '#D55E00',
  '#F0E442', '#000000'];

function element(tag, attributes = {}, children = []) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  for (const child of children) node.append(child);
  return node;
}

function section(title, note) {
  const node = element('section', {}, [element('h2', {}, [title])]);
  if (note) node.append(element('p', { class: 'note' }, [note]));
  return node;
}

// Figure 3: disliked red, liked green, brightness by the degree (|value| / 5).
export function sliderColor(value) {
  const v = Math.max(-1, Math.min(1, value / 5));
  const level = Math.round(40 + 215 * Math.abs(v));
  return v < 0 ? `rgb(${level},30,30)` : v > 0 ? `rgb(30,${level},30)` : 'rgb(40,40,40)';
}

const kWidth = 900;

// A strip with one column per frame, coloured by `colorOf(frame)`.
function strip(frames, colorOf, height = 18, title = '') {
  const canvas = element('canvas', { width: kWidth, height, class: 'strip', title });
  const g = canvas.getContext('2d');
  for (let x = 0; x < kWidth; ++x) {
    const frame = Math.min(frames - 1, Math.floor((x / kWidth) * frames));
    g.fillStyle = colorOf(frame);
    g.fillRect(x, 0, 1, height);
  }
  return canvas;
}

function row(label, content) {
  return element('div', { class: 'row' }, [element('span', { class: 'label' }, [label]), content]);
}

export function annotationSection(data) {
  const node = section('Annotations',
    'Slider values of every take: red dislike, green like, brighter for stronger (paper Figure 3); ' +
    'as recorded on the take\'s own timeline and warped to the reference timeline (eq. 6).');
  for (const take of data.takes) {
    node.append(row(`${take.name} recorded`,
      strip(take.annotation.length, (f) => sliderColor(take.annotation[f]), 18, take.name)));
    node.append(row(`${take.name} warped`,
      strip(take.warped_annotation.length, (f) => sliderColor(take.warped_annotation[f]))));
  }
  return node;
}

export function segmentSection(data, listeners) {
  const node = section('Segments and transitions',
    'The take chosen for every reference frame (labels l_t, eq. 7) and the montage\'s segments ' +
    'on its own timeline; black lines are transitions, pink bars spatial markers (Figure 5).');
  const n = data.labels.length;
  const reference = strip(n, (f) => takeColors[data.labels[f] % takeColors.length], 24);
  const montageFrames = data.montage.frames;
  const segmentOf = (f) => data.segments.find((s) => f >= s.montage_first && f <= s.montage_last);
  const montage = strip(montageFrames, (f) => {
    const s = segmentOf(f);
    return s ? takeColors[s.take % takeColors.length] : '#888';
  }, 24);
  const g = montage.getContext('2d');
  const gr = reference.getContext('2d');
  g.fillStyle = '#000';
  gr.fillStyle = '#000';
  for (const s of data.segments.slice(1)) {
    g.fillRect(Math.round((s.montage_first / montageFrames) * kWidth), 0, 2, 24);
    gr.fillRect(Math.round((s.reference_first / n) * kWidth), 0, 2, 24);
  }
  g.fillStyle = '#ff69b4';
  for (const frame of data.markers) g.fillRect(Math.round((frame / montageFrames) * kWidth) - 2, 0, 5, 24);
  node.append(row('reference timeline', reference));
  node.append(row('montage', montage));
  // The scrubber's montage frame and the reference frame it was played from.
  const cursor = element('div', { class: 'cursor' });
  const referenceCursor = element('div', { class: 'cursor' });
  montage.parentElement.style.position = 'relative';
  montage.parentElement.append(cursor);
  reference.parentElement.style.position = 'relative';
  reference.parentElement.append(referenceCursor);
  listeners.push((frame, t) => {
    cursor.style.left = `${montage.offsetLeft + (frame / montageFrames) * montage.clientWidth}px`;
    referenceCursor.style.left = `${reference.offsetLeft + (t / n) * reference.clientWidth}px`;
  });
  const legend = element('p', { class: 'legend' });
  data.takes.forEach((take, l) => {
    legend.append(element('span', { style: `background:${takeColors[l % takeColors.length]}` }, ['\u00a0\u00a0\u00a0']),
      ` ${take.name}   `);
  });
  node.append(legend);
  const table = {
    title: 'Segments', columns: ['take', 'reference frames', 'source frames', 'montage frames'],
    rows: data.segments.map((s) => [data.takes[s.take].name, `${s.reference_first}-${s.reference_last}`,
      `${s.source_first}-${s.source_last}`, `${s.montage_first}-${s.montage_last}`]),
  };
  node.append(tableElement(table));
  return node;
}

function decodeBytes(text) {
  const binary = atob(text);
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

export function dtwSection(data) {
  const node = section('Time warps',
    'Matching cost C_match (eq. 5) between the reference take (x) and each take (y, up), darker ' +
    'is a better match (paper Figure 4); yellow: the optimal warp w_l(t), green: the linear warp.');
  const grid = element('div', { class: 'dtw' });
  for (const image of data.dtw) {
    const [rows, columns] = image.size;
    const size = 280;
    const canvas = element('canvas', { width: size, height: size });
    const g = canvas.getContext('2d');
    const pixels = g.createImageData(columns, rows);
    const bytes = decodeBytes(image.cost);
    for (let i = 0; i < rows * columns; ++i) {
      const r = Math.floor(i / columns), c = i % columns;
      const o = 4 * ((rows - 1 - r) * columns + c);  // source frames upwards
      pixels.data[o] = pixels.data[o + 1] = pixels.data[o + 2] = bytes[i];
      pixels.data[o + 3] = 255;
    }
    const small = element('canvas', { width: columns, height: rows });
    small.getContext('2d').putImageData(pixels, 0, 0);
    g.imageSmoothingEnabled = false;
    g.drawImage(small, 0, 0, size, size);
    const n = image.reference_frames, m = image.source_frames;
    const line = (points, color) => {
      g.strokeStyle = color;
      g.lineWidth = 2;
      g.beginPath();
      points.forEach(([t, w], i) => {
        const x = (t / Math.max(1, n - 1)) * size, y = size - (w / Math.max(1, m - 1)) * size;
        if (i === 0) g.moveTo(x, y); else g.lineTo(x, y);
      });
      g.stroke();
    };
    line([[0, 0], [n - 1, m - 1]], '#3c3');
    const warp = data.takes[image.take].warp;
    line(warp.map((w, t) => [t, w]), '#ff0');
    grid.append(element('figure', {}, [canvas, element('figcaption', {},
      [`${data.takes[image.take].name}: ${m} frames against ${n}; DTW cost ${image.dtw_cost ?? ''}`])]));
  }
  node.append(grid);
  return node;
}

function tableElement(table) {
  const head = element('tr', {}, table.columns.map((c) => element('th', {}, [String(c)])));
  const body = table.rows.map((r) => element('tr', {}, r.map((v) => element('td', {}, [String(v)]))));
  return element('table', {}, [element('caption', {}, [table.title]), element('thead', {}, [head]),
    element('tbody', {}, body)]);
}

export function tableSection(table) {
  const node = section(table.title, table.note);
  const content = tableElement({ ...table, title: table.file || '' });
  if (table.rows.length <= 40) {
    node.append(content);
  } else {
    // Long tables (a run's metrics.csv) start folded.
    const details = element('details', {}, [element('summary', {}, [`${table.rows.length} rows`])]);
    details.append(content);
    node.append(details);
  }
  return node;
}

export function figureSection(figure) {
  const node = section(figure.title, figure.note);
  const holder = element('div', { class: 'figure' });
  // The study's own SVG (study/svg_chart.cc), inlined as written.
  holder.innerHTML = figure.svg;
  node.append(holder);
  return node;
}

export function textSection(text) {
  const node = section(text.title, text.note);
  node.append(element('pre', {}, [text.text]));
  return node;
}
