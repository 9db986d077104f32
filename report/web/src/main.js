// mmh's HTML report: reads the data mmh embedded in the page (#mmh-data, #mmh-glb) and draws the
// report of a compose, run, study, stats or sweep folder. Bundled by esbuild at build time (report/CMakeLists.txt);
// the page needs no network.
import { annotationSection, dtwSection, segmentSection, tableSection, figureSection, textSection }
  from './figures.js';
import { View3d } from './view3d.js';
import { sweepPlanSection, sweepPlotsSection, drawnPlots } from './sweep.js';

// Errors are collected for the browser test (report/web/tools/browser_check.js) and shown.
const errors = [];
window.addEventListener('error', (event) => errors.push(String(event.message)));
window.addEventListener('unhandledrejection', (event) => errors.push(String(event.reason)));

function element(tag, attributes = {}, children = []) {
  const node = document.createElement(tag);
  for (const [key, value] of Object.entries(attributes)) node.setAttribute(key, value);
  for (const child of children) node.append(child);
  return node;
}

function decodeBase64(text) {
  const binary = atob(text.trim());
  const bytes = new Uint8Array(binary.length);
  for (let i = 0; i < binary.length; ++i) bytes[i] = binary.charCodeAt(i);
  return bytes;
}

// For the browser test: what the page shows, read back from the DOM (tables, the sweep's plots
// and its cell counts).
function inspect() {
  const text = (node) => node.textContent;
  return {
    tables: [...document.querySelectorAll('table')].map((table) => ({
      caption: table.caption ? text(table.caption) : '',
      columns: [...table.querySelectorAll('thead th')].map(text),
      rows: [...table.querySelectorAll('tbody tr')].map((tr) => [...tr.children].map(text)),
    })),
    plots: drawnPlots(),
    figures: document.querySelectorAll('.figure svg').length,
    cells: Object.fromEntries([...document.querySelectorAll('.cell-state')].map(
      (span) => [span.dataset.state, parseInt(span.textContent, 10)])),
  };
}

async function main() {
  const data = JSON.parse(document.getElementById('mmh-data').textContent);
  const app = document.getElementById('app');
  app.append(element('h1', {}, [data.title]));
  app.append(element('p', { class: 'folder' }, [`${data.kind} folder: ${data.folder}`]));
  const api = { data, errors, view: null, ready: false, inspect };
  window.mmhReport = api;

  if (data.kind === 'compose' || data.kind === 'run') {
    const glbElement = document.getElementById('mmh-glb');
    const scrubberHost = element('section', { class: 'view' });
    app.append(scrubberHost);
    const listeners = [];
    if (glbElement) {
      api.view = new View3d(scrubberHost, data.montage, data.clock,
        (frame, t) => listeners.forEach((f) => f(frame, t)));
      await api.view.load(decodeBase64(glbElement.textContent).buffer);
    }
    app.append(segmentSection(data, listeners));
    app.append(annotationSection(data));
    app.append(dtwSection(data));
  }
  if (data.kind === 'sweep') {
    app.append(sweepPlanSection(data.sweep));
    app.append(sweepPlotsSection(data.plots));
  }
  for (const figure of data.figures || []) app.append(figureSection(figure));
  for (const text of data.texts || []) app.append(textSection(text));
  for (const table of data.tables || []) app.append(tableSection(table));
  api.ready = true;
  document.body.dataset.ready = 'true';
}

main().catch((error) => {
  errors.push(String(error && error.stack ? error.stack : error));
  console.error(error);
  document.body.append(element('pre', { class: 'error' }, [String(error)]));
});
