// The web page of rcfd-server (docs/web.md): sign in with the server's token, follow jobs, submit new
// ones from an example scene or a pasted JSON, upload field databases, compare coverage distributions.
// Plain modern JavaScript, no build step, no library: views are built with DOM calls (text is set as
// text, never parsed as HTML), and the route is the URL's fragment (#/jobs, #/jobs/ID, ...).

import { api, ApiError, download, objectUrl, session, uploadDatabase } from './api.js';
import { coverageChart } from './chart.js';
import { humanDuration } from './format.js';

const FINAL = new Set(['SUCCEEDED', 'FAILED', 'CANCELLED']);
const PAGE_SIZE = 20;
const POLL_MS = 1500;
const main = document.getElementById('main');

// ---------------------------------------------------------------- helpers

/// An element: h('a', {href: '#/jobs', class: 'x', onclick: f}, 'text', child, ...).
function h(tag, attrs = {}, ...children) {
  const node = document.createElement(tag);
  for (const [k, v] of Object.entries(attrs)) {
    if (v === undefined || v === null || v === false) continue;
    if (k.startsWith('on')) node.addEventListener(k.slice(2), v);
    else if (v === true) node.setAttribute(k, '');
    else node.setAttribute(k, String(v));
  }
  for (const c of children.flat()) if (c !== undefined && c !== null && c !== false) node.append(c);
  return node;
}

const shortId = (id) => id.slice(0, 8);
const percent = (f) => `${Math.round((f ?? 0) * 100)} %`;
const number = (v, digits = 3) => (typeof v === 'number' ? Number(v.toPrecision(digits)).toString() : '—');
const when = (iso) => (iso ? new Date(iso).toLocaleString() : '—');

function bytes(n) {
  const units = ['B', 'KiB', 'MiB', 'GiB', 'TiB'];
  let i = 0;
  while (n >= 1024 && i < units.length - 1) { n /= 1024; i++; }
  return `${Number(n.toPrecision(3))} ${units[i]}`;
}

function progressBar(job) {
  const fraction = job.state === 'SUCCEEDED' ? 1 : job.progress?.fraction ?? 0;
  return h('span', { class: 'progress' },
    h('progress', { max: 1, value: fraction, 'aria-label': `progress of job ${shortId(job.id)}` }),
    h('span', { class: 'progress-text' }, percent(fraction)));
}

function stateBadge(state) {
  return h('span', { class: `state state-${state.toLowerCase()}` }, state);
}

function message(text, kind = 'info') {
  return h('p', { class: `message message-${kind}`, role: kind === 'error' ? 'alert' : 'status' }, text);
}

function errorText(e) {
  if (e instanceof ApiError) {
    const lines = [e.message, ...e.errors.map((v) => `${v.pointer}: ${v.message}`)];
    return lines.join('\n');
  }
  return String(e?.message || e);
}

function heading(text) {
  const h1 = h('h1', { tabindex: -1 }, text);
  return h1;
}

/// Calls `tick` now and every POLL_MS until it returns false or the view is left.
function poll(signal, tick) {
  let timer = null;
  const run = async () => {
    if (signal.aborted) return;
    let again = true;
    try { again = await tick(); } catch (e) { if (e instanceof ApiError && e.status === 401) return; }
    if (again !== false && !signal.aborted) timer = setTimeout(run, POLL_MS);
  };
  signal.addEventListener('abort', () => clearTimeout(timer));
  run();
}

// ---------------------------------------------------------------- sign in

function signInView() {
  const input = h('input', { id: 'token', name: 'token', type: 'password', autocomplete: 'off', required: true,
    'aria-describedby': 'token-help' });
  const status = h('div', { 'aria-live': 'polite' });
  const form = h('form', { class: 'card narrow', novalidate: true },
    h('p', {}, h('label', { for: 'token' }, 'Token')),
    h('p', {}, input),
    h('p', { id: 'token-help', class: 'help' },
      'The server\'s bearer token (the file DATA_DIR/token, --token-file, or yours from its users file). ' +
      'It is kept for this browser tab only.'),
    h('p', {}, h('button', { type: 'submit' }, 'Sign in')),
    status);
  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    status.replaceChildren();
    const token = input.value.trim();
    if (!token) {
      status.append(message('Type the token first.', 'error'));
      input.focus();
      return;
    }
    try {
      await api('/v1/jobs?page_size=1', { token });
      session.signIn(token);
      input.value = '';
      // Back to the view the user came for (a job's link), or the job list.
      const target = location.hash && location.hash !== '#/signin' ? location.hash : '#/jobs';
      if (location.hash === target) route();
      else location.hash = target;
    } catch (err) {
      status.append(message(err.status === 401 ? 'The server does not know this token.' : errorText(err), 'error'));
      input.focus();
    }
  });
  return [heading('Sign in'), form];
}

// ---------------------------------------------------------------- jobs list

function jobsView(signal, query) {
  const state = query.get('state') || '';
  const kind = query.get('kind') || '';
  const tokens = [''];  // page tokens of the pages seen so far (the first page has none)
  let page = 0;
  const rows = new Map();
  const tbody = h('tbody');
  const pageLabel = h('span', { class: 'page-label', 'aria-live': 'polite' });
  const status = h('div');
  const prev = h('button', { type: 'button', onclick: () => { page--; rows.clear(); tbody.replaceChildren(); refresh(); } }, 'Previous page');
  const next = h('button', { type: 'button', onclick: () => { page++; rows.clear(); tbody.replaceChildren(); refresh(); } }, 'Next page');

  const select = (id, label, value, options) => h('label', { for: id }, label, ' ',
    h('select', { id, onchange: () => setFilters() },
      options.map(([v, text]) => h('option', { value: v, selected: v === value }, text))));
  const filters = h('form', { class: 'filters', onsubmit: (e) => e.preventDefault() },
    select('filter-state', 'State', state, [['', 'any'], ...['QUEUED', 'RUNNING', 'CANCELLING', 'SUCCEEDED', 'FAILED', 'CANCELLED'].map((s) => [s, s])]),
    select('filter-kind', 'Kind', kind, [['', 'any'], ['database', 'database'], ['calibration', 'calibration'], ['spray', 'spray']]));
  function setFilters() {
    const q = new URLSearchParams();
    const s = document.getElementById('filter-state').value, k = document.getElementById('filter-kind').value;
    if (s) q.set('state', s);
    if (k) q.set('kind', k);
    location.hash = `#/jobs${q.toString() ? `?${q}` : ''}`;
  }

  function row(job) {
    let r = rows.get(job.id);
    if (!r) {
      r = {
        tr: h('tr', { 'data-job': job.id }),
        kind: h('td', { 'data-label': 'Kind' }), state: h('td', { 'data-label': 'State' }),
        progress: h('td', { 'data-label': 'Progress' }), eta: h('td', { 'data-label': 'ETA' }),
        created: h('td', { 'data-label': 'Submitted' }),
      };
      r.tr.append(h('th', { scope: 'row', 'data-label': 'Job' }, h('a', { href: `#/jobs/${job.id}`, title: job.id }, shortId(job.id))),
        r.kind, r.state, r.progress, r.eta, r.created);
      rows.set(job.id, r);
    }
    r.kind.textContent = job.kind;
    r.state.replaceChildren(stateBadge(job.state));
    const bar = r.progress.querySelector('progress');
    const fraction = job.state === 'SUCCEEDED' ? 1 : job.progress?.fraction ?? 0;
    if (bar) {  // updated in place: a focused link or a screen reader's position survives the poll
      bar.value = fraction;
      r.progress.querySelector('.progress-text').textContent = percent(fraction) + (job.progress?.phase ? ` · ${job.progress.phase}` : '');
    } else {
      r.progress.append(progressBar(job));
    }
    r.eta.textContent = FINAL.has(job.state) ? '—' : humanDuration(job.progress?.eta_s);
    r.created.textContent = when(job.created_at);
    return r.tr;
  }

  async function refresh() {
    const q = new URLSearchParams({ page_size: PAGE_SIZE });
    if (state) q.set('state', state);
    if (kind) q.set('kind', kind);
    if (tokens[page]) q.set('page_token', tokens[page]);
    try {
      const list = await api(`/v1/jobs?${q}`);
      if (list.next_page_token) tokens[page + 1] = list.next_page_token;
      else tokens.length = page + 1;
      const ids = new Set(list.jobs.map((j) => j.id));
      for (const [id, r] of rows) if (!ids.has(id)) { r.tr.remove(); rows.delete(id); }
      list.jobs.forEach((job) => tbody.append(row(job)));  // append moves existing rows into order
      prev.disabled = page === 0;
      next.disabled = !tokens[page + 1];
      pageLabel.textContent = `Page ${page + 1}`;
      status.replaceChildren(list.jobs.length ? '' : message(page === 0 ? 'No jobs yet. Submit one.' : 'No more jobs.'));
      return true;
    } catch (e) {
      status.replaceChildren(message(errorText(e), 'error'));
      return true;
    }
  }
  poll(signal, refresh);
  return [
    heading('Jobs'),
    h('p', { class: 'help' }, 'Oldest first; progress and ETA update by themselves.'),
    filters,
    h('table', { class: 'jobs' },
      h('caption', { class: 'visually-hidden' }, 'Jobs with their state, progress and estimated time left'),
      h('thead', {}, h('tr', {}, ['Job', 'Kind', 'State', 'Progress', 'ETA', 'Submitted'].map((t) => h('th', { scope: 'col' }, t)))),
      tbody),
    status,
    h('nav', { class: 'pager', 'aria-label': 'Pages' }, prev, pageLabel, next),
  ];
}

// ---------------------------------------------------------------- one job

async function coverageOf(id) {
  const [coverage, summary, job] = await Promise.all([
    api(`/v1/jobs/${id}/coverage?format=json`),
    api(`/v1/jobs/${id}/result`),
    api(`/v1/jobs/${id}?view=full`),
  ]);
  const scene = job.request?.scene?.name;
  return { id, coverage, summary, label: `${scene ? `${scene} ` : ''}(job ${shortId(id)})` };
}

function seriesOf(c) {
  const e = c.coverage.ensemble;
  return {
    label: c.label, edges: c.coverage.edges, counts: c.coverage.counts,
    band: e ? { low: e.ci95_low, high: e.ci95_high, mean: e.mean } : undefined,
  };
}

function statsTable(items) {
  const stat = (c, key) => number(c.summary.coverage?.[key]);
  return h('table', { class: 'stats' },
    h('caption', {}, 'Coverage statistics'),
    h('thead', {}, h('tr', {}, h('th', { scope: 'col' }, 'Job'),
      ['mean', 'median', 'p10', 'p90', 'overspray'].map((t) => h('th', { scope: 'col' }, t)))),
    h('tbody', {}, items.map((c, i) => h('tr', {},
      h('th', { scope: 'row' }, h('span', { class: `swatch swatch-${i}`, 'aria-hidden': 'true' }), ' ', h('a', { href: `#/jobs/${c.id}` }, c.label)),
      ['mean', 'median', 'p10', 'p90'].map((k) => h('td', { 'data-label': k }, stat(c, k))),
      h('td', { 'data-label': 'overspray' }, typeof c.summary.overspray_fraction === 'number' ? percent(c.summary.overspray_fraction) : '—')))));
}

function coverageSection(items) {
  const title = items.length > 1 ? 'Coverage distributions' : 'Coverage distribution';
  const bands = items.some((c) => c.coverage.ensemble);
  return h('section', { class: 'coverage', 'aria-labelledby': 'coverage-heading' },
    h('h2', { id: 'coverage-heading' }, title),
    h('figure', {}, coverageChart(items.map(seriesOf), { title }),
      h('figcaption', {}, items.length > 1 ? 'Outlined: each job\'s fraction of particles per coverage bin' : 'Bars: fraction of particles per coverage bin',
        bands ? '; shaded: the 95 % interval of the ensemble mean' : '', '.')),
    statsTable(items));
}

function jobView(signal, id) {
  const title = heading(`Job ${shortId(id)}`);
  const facts = h('dl', { class: 'facts' });
  const actions = h('div', { class: 'actions' });
  const status = h('div', { 'aria-live': 'polite' });
  const results = h('div');
  let shownFinal = false;

  const fact = (term, ...value) => [h('dt', {}, term), h('dd', {}, ...value)];
  let shownState = null;
  function renderFacts(job) {
    title.textContent = `${job.kind[0].toUpperCase()}${job.kind.slice(1)} job ${shortId(job.id)}`;
    // Redrawn on every poll unless the keyboard is in them (the focus would be lost).
    if (!facts.contains(document.activeElement)) facts.replaceChildren(
      ...fact('State', stateBadge(job.state)),
      ...fact('Progress', progressBar(job), job.progress?.phase ? ` phase ${job.progress.phase}` : ''),
      ...fact('ETA', FINAL.has(job.state) ? '—' : humanDuration(job.progress?.eta_s)),
      ...fact('Simulated', job.progress?.sim_time != null ? humanDuration(job.progress.sim_time) : '—'),
      ...fact('Database', job.database ? h('a', { href: `#/jobs/${job.database}` }, shortId(job.database)) : '—'),
      ...fact('Submitted', when(job.created_at)),
      ...fact('Finished', when(job.finished_at)),
      ...fact('Owner', job.owner ?? '—'),
      ...fact('Id', h('code', {}, job.id)),
      ...(job.error ? fact('Error', h('pre', { class: 'error-text' }, job.error)) : []));
    if (job.state === shownState) return;  // the buttons keep their focus while the state stays
    shownState = job.state;
    actions.replaceChildren();
    if (!FINAL.has(job.state) && job.state !== 'CANCELLING') {
      actions.append(h('button', { type: 'button', class: 'danger', onclick: async (e) => {
        e.target.disabled = true;
        try {
          await api(`/v1/jobs/${id}:cancel`, { method: 'POST' });
          status.replaceChildren(message('Cancel requested.'));
        } catch (err) { status.replaceChildren(message(errorText(err), 'error')); e.target.disabled = false; }
      } }, 'Cancel job'));
    }
    if (job.state === 'FAILED' || job.state === 'CANCELLED') {
      actions.append(h('button', { type: 'button', onclick: async () => {
        try {
          await api(`/v1/jobs/${id}:retry`, { method: 'POST' });
          shownFinal = false;
          results.replaceChildren();
          watch();
        }
        catch (err) { status.replaceChildren(message(errorText(err), 'error')); }
      } }, 'Retry'));
    }
    if (job.kind === 'spray' && job.state === 'SUCCEEDED')
      actions.append(h('a', { class: 'button', href: `#/compare?a=${id}` }, 'Compare coverage'));
  }

  function downloadButton(label, path, filename) {
    return h('button', { type: 'button', class: 'download', 'data-file': filename, onclick: async (e) => {
      e.target.disabled = true;
      try { await download(path, filename); status.replaceChildren(message(`Downloaded ${filename}.`)); }
      catch (err) { status.replaceChildren(message(errorText(err), 'error')); }
      e.target.disabled = false;
    } }, label);
  }

  async function renderResults(job) {
    const parts = [];
    const artifacts = job.artifacts ?? [];
    if (job.kind === 'spray' && job.state === 'SUCCEEDED') {
      try { parts.push(coverageSection([await coverageOf(id)])); }
      catch (e) { parts.push(message(errorText(e), 'error')); }
    }
    if (job.state === 'SUCCEEDED') {
      try {
        const summary = await api(`/v1/jobs/${id}/result`);
        parts.push(h('section', {}, h('h2', {}, 'Summary'), summaryFacts(job.kind, summary),
          h('details', {}, h('summary', {}, 'summary.json'), h('pre', { class: 'json' }, JSON.stringify(summary, null, 2)))));
      } catch (e) { parts.push(message(errorText(e), 'error')); }
    }
    const figures = artifacts.filter((a) => a.endsWith('.svg'));
    if (figures.length) {
      const list = h('div', { class: 'figures' });
      parts.push(h('section', {}, h('h2', {}, 'Figures'), list));
      for (const name of figures) {
        const img = h('img', { alt: `figure ${name}`, 'data-figure': name });
        list.append(h('figure', {}, img, h('figcaption', {}, name)));
        objectUrl(`/v1/jobs/${id}/artifacts/${name}`).then((url) => {
          img.src = url;
          signal.addEventListener('abort', () => URL.revokeObjectURL(url));
        }).catch((e) => img.replaceWith(message(errorText(e), 'error')));
      }
    }
    const downloads = h('div', { class: 'downloads' });
    if (job.kind === 'spray' && job.state === 'SUCCEEDED') {
      downloads.append(downloadButton('Coverage CSV', `/v1/jobs/${id}/coverage?format=csv`, `coverage-${shortId(id)}.csv`),
        downloadButton('Coverage HDF5', `/v1/jobs/${id}/coverage?format=h5`, `coverage-${shortId(id)}.h5`));
    }
    for (const name of artifacts) downloads.append(downloadButton(name, `/v1/jobs/${id}/artifacts/${name}`, name));
    if (downloads.childElementCount) parts.push(h('section', {}, h('h2', {}, 'Downloads'), downloads));
    results.replaceChildren(...parts);
  }

  async function renderJobFile() {
    try {
      const full = await api(`/v1/jobs/${id}?view=full`);
      jobFile.replaceChildren(h('pre', { class: 'json' }, JSON.stringify(full.request, null, 2)));
    } catch (e) { jobFile.replaceChildren(message(errorText(e), 'error')); }
  }
  const jobFile = h('div');
  const events = h('ol', { class: 'events' });

  const tick = async () => {
    let job;
    try { job = await api(`/v1/jobs/${id}`); }
    catch (e) {
      status.replaceChildren(message(e.status === 404 ? 'There is no such job (or it is another user\'s).' : errorText(e), 'error'));
      return e.status !== 404;
    }
    renderFacts(job);
    const ev = await api(`/v1/jobs/${id}/events`);
    events.replaceChildren(...ev.events.map((x) => h('li', {}, `${when(x.at)}: ${x.from ?? '—'} → ${x.to}`, x.reason ? ` (${x.reason})` : '')));
    if (FINAL.has(job.state) && !shownFinal) {
      shownFinal = true;
      await renderResults(job);
    }
    return !FINAL.has(job.state) || !shownFinal;
  };
  const watch = () => poll(signal, tick);
  watch();
  renderJobFile();
  return [
    title, facts, actions, status, results,
    h('section', {}, h('h2', {}, 'Job file'), h('p', { class: 'help' }, 'As submitted.'), jobFile),
    h('section', {}, h('h2', {}, 'Events'), events),
  ];
}

function summaryFacts(kind, s) {
  const rows = [];
  const add = (term, value) => { if (value !== undefined && value !== null) rows.push(h('dt', {}, term), h('dd', {}, String(value))); };
  if (kind === 'spray') {
    add('Coverage mean', number(s.coverage?.mean));
    add('Coverage median', number(s.coverage?.median));
    add('Coverage p10 / p90', `${number(s.coverage?.p10)} / ${number(s.coverage?.p90)}`);
    if (typeof s.overspray_fraction === 'number') add('Overspray', percent(s.overspray_fraction));
  }
  if (kind === 'calibration') add('Selected D0 [m²/s]', s.selected_d0);
  if (typeof s.sim_time === 'number') add('Simulated time', humanDuration(s.sim_time));
  if (typeof s.wall_time === 'number') add('Wall time', humanDuration(s.wall_time));
  return h('dl', { class: 'facts' }, rows);
}

// ---------------------------------------------------------------- submit

// Form fields by the JSON pointer of the job member they set: a violation the server reports at such a
// pointer (or below it) is shown beside that field.
const FIELD_OF_POINTER = [
  ['/kind', 'f-kind'], ['/database', 'f-database'], ['/duration', 'f-duration'], ['/seed', 'f-seed'],
  ['/discard', 'f-discard'], ['/d0_values', 'f-d0-values'], ['/scene/rcfd/tracers', 'f-tracers'],
  ['/scene/rcfd/d0', 'f-d0'], ['/ensemble', 'f-ensemble'],
];

export function fieldOfPointer(pointer, sceneField) {
  for (const [prefix, field] of FIELD_OF_POINTER)
    if (pointer === prefix || pointer.startsWith(`${prefix}/`)) return field;
  if (pointer === '/scene' || pointer.startsWith('/scene/')) return sceneField;
  return null;
}

const KIND_FIELDS = {
  database: ['f-seed'],
  calibration: ['f-database', 'f-seed', 'f-duration', 'f-discard', 'f-d0-values', 'f-tracers'],
  spray: ['f-database', 'f-seed', 'f-duration', 'f-tracers', 'f-d0', 'f-ensemble'],
  pipeline: ['f-database', 'f-seed', 'f-duration', 'f-calibration-duration', 'f-discard', 'f-d0-values', 'f-tracers'],
};

function submitView(signal, query) {
  const status = h('div', { class: 'submit-status', 'aria-live': 'polite' });
  const summary = h('div', { id: 'error-summary' });
  const field = (id, label, input, help) => {
    const control = input.id === id ? input : input.querySelector(`#${id}`);
    if (help && control) control.setAttribute('aria-describedby', `${id}-help`);
    return h('div', { class: 'field', id: `${id}-field` },
      h('label', { for: id }, label), input,
      help ? h('p', { class: 'help', id: `${id}-help` }, help) : null,
      h('p', { class: 'field-error', id: `${id}-error`, hidden: true }));
  };
  const text = (id, value = '', extra = {}) => h('input', { id, name: id, type: 'text', value, autocomplete: 'off', ...extra });

  const source = h('fieldset', { class: 'source' }, h('legend', {}, 'Scene'),
    h('label', {}, h('input', { type: 'radio', name: 'source', value: 'example', checked: true, onchange: sourceChanged }), ' An example scene'),
    h('label', {}, h('input', { type: 'radio', name: 'source', value: 'json', onchange: sourceChanged }), ' Paste or upload a scene or job (JSON)'));
  const exampleSelect = h('select', { id: 'f-example' });
  const jsonArea = h('textarea', { id: 'f-json', rows: 12, spellcheck: 'false' });
  const fileInput = h('input', { id: 'f-file', type: 'file', accept: '.json,application/json' });
  fileInput.addEventListener('change', async () => { if (fileInput.files[0]) jsonArea.value = await fileInput.files[0].text(); });
  const kindSelect = h('select', { id: 'f-kind', onchange: kindChanged },
    h('option', { value: 'database' }, 'database: CFD-DEM of the scene sampled into a field database'),
    h('option', { value: 'calibration' }, 'calibration: the D0 sweep against a database'),
    h('option', { value: 'spray', selected: true }, 'spray: coating on a database'),
    h('option', { value: 'pipeline' }, 'calibration, then spray with the selected D0'));
  const databaseSelect = h('select', { id: 'f-database' }, h('option', { value: '' }, '(none)'));

  const exampleField = field('f-example', 'Example scene', exampleSelect, 'A scene of the repository\'s examples/ folder.');
  const jsonField = field('f-json', 'Scene or job JSON', h('div', {}, jsonArea, h('p', {}, h('label', { for: 'f-file' }, 'or a file: '), fileInput)),
    'A job (with "kind") is sent as it is; a scene is sent with the fields below.');
  jsonField.hidden = true;
  const fields = h('div', { class: 'grid' },
    field('f-kind', 'Kind', kindSelect),
    field('f-database', 'Database', databaseSelect, 'An uploaded database or a database job (it may still run).'),
    field('f-duration', 'Duration [s]', text('f-duration', '1', { inputmode: 'decimal' }), 'Simulated time (spray; calibration: per D0 value).'),
    field('f-calibration-duration', 'Calibration duration [s]', text('f-calibration-duration', '10', { inputmode: 'decimal' }), 'Simulated time per D0 value.'),
    field('f-seed', 'Seed', text('f-seed', '1', { inputmode: 'numeric' })),
    field('f-tracers', 'Tracers', text('f-tracers', '', { inputmode: 'numeric' }), 'Empty: the scene\'s own.'),
    field('f-d0', 'D0 [m²/s]', text('f-d0', '', { inputmode: 'decimal' }), 'Empty: the scene\'s own.'),
    field('f-ensemble', 'Ensemble members', text('f-ensemble', '', { inputmode: 'numeric' }), 'Empty: one run.'),
    field('f-discard', 'Discard [s]', text('f-discard', '2', { inputmode: 'decimal' }), 'Calibration: seconds ignored at the start.'),
    field('f-d0-values', 'D0 values [m²/s]', text('f-d0-values', '0, 1e-5, 1e-4, 5e-4, 1e-3, 1e-2'), 'Calibration: comma-separated.'));

  const submitButton = h('button', { type: 'submit' }, 'Submit');
  const form = h('form', { class: 'card', novalidate: true }, source, exampleField, jsonField, fields, summary, h('p', {}, submitButton), status);

  function sourceChanged() {
    const json = form.querySelector('input[name=source]:checked').value === 'json';
    exampleField.hidden = json;
    jsonField.hidden = !json;
  }
  function kindChanged() {
    const shown = new Set(KIND_FIELDS[kindSelect.value]);
    for (const id of ['f-database', 'f-duration', 'f-calibration-duration', 'f-seed', 'f-tracers', 'f-d0', 'f-ensemble', 'f-discard', 'f-d0-values'])
      document.getElementById(`${id}-field`).hidden = !shown.has(id);
  }

  function clearErrors() {
    summary.replaceChildren();
    for (const p of form.querySelectorAll('.field-error')) { p.hidden = true; p.textContent = ''; }
    for (const i of form.querySelectorAll('[aria-invalid]')) {
      i.removeAttribute('aria-invalid');
      i.setAttribute('aria-describedby', (i.getAttribute('aria-describedby') || '').split(' ').filter((x) => !x.endsWith('-error')).join(' '));
    }
  }
  /// Shows the violations: each beside the field its pointer maps to, and all of them in a list.
  function showErrors(title, violations, sceneField, fieldOverrides = {}) {
    const items = [];
    let first = null;
    for (const v of violations) {
      const id = v.field ?? fieldOverrides[v.pointer] ?? fieldOfPointer(v.pointer, sceneField);
      const visible = id && !document.getElementById(`${id}-field`).hidden ? id : null;
      if (visible) {
        const p = document.getElementById(`${visible}-error`);
        p.hidden = false;
        p.textContent = (p.textContent ? `${p.textContent}\n` : '') + (v.pointer.startsWith('/scene/') && visible === sceneField ? `${v.pointer}: ${v.message}` : v.message);
        const input = document.getElementById(visible);
        input.setAttribute('aria-invalid', 'true');
        input.setAttribute('aria-describedby', `${input.getAttribute('aria-describedby') || ''} ${visible}-error`.trim());
        first ??= input;
      }
      items.push(h('li', {}, visible ? h('a', { href: `#${visible}`, onclick: (e) => { e.preventDefault(); document.getElementById(visible).focus(); } }, h('code', {}, v.pointer || '(the document)')) : h('code', {}, v.pointer || '(the document)'), `: ${v.message}`));
    }
    summary.replaceChildren(h('div', { class: 'message message-error', role: 'alert', tabindex: -1 },
      h('p', {}, title), items.length ? h('ul', { class: 'violations' }, items) : null));
    (first ?? summary.firstChild).focus();
  }

  const numberOrRaw = (v) => (v.trim() === '' ? undefined : Number.isFinite(Number(v)) ? Number(v) : v.trim());

  async function sceneOf() {
    if (form.querySelector('input[name=source]:checked').value === 'example')
      return { scene: await api(`/v1/examples/${encodeURIComponent(exampleSelect.value)}`), field: 'f-example' };
    let doc;
    try { doc = JSON.parse(jsonArea.value); }
    catch (e) { throw Object.assign(new Error('local'), { violations: [{ pointer: '', field: 'f-json', message: `not JSON: ${e.message}` }] }); }
    if (doc && typeof doc === 'object' && !Array.isArray(doc) && 'kind' in doc) return { job: doc, field: 'f-json' };
    return { scene: doc, field: 'f-json' };
  }

  function jobOf(kind, scene) {
    const value = (id) => document.getElementById(id).value;
    const s = structuredClone(scene);
    const tracers = numberOrRaw(value('f-tracers')), d0 = numberOrRaw(value('f-d0'));
    const shown = (id) => !document.getElementById(`${id}-field`).hidden;
    if (kind !== 'database' && tracers !== undefined && shown('f-tracers')) (s.rcfd ??= {}).tracers = tracers;
    if (kind === 'spray' && d0 !== undefined && shown('f-d0')) (s.rcfd ??= {}).d0 = d0;
    const job = { kind, scene: s };
    const seed = numberOrRaw(value('f-seed'));
    if (seed !== undefined) job.seed = seed;
    if (kind !== 'database') {
      if (value('f-database')) job.database = value('f-database');
      const duration = numberOrRaw(value('f-duration'));
      if (duration !== undefined) job.duration = duration;
    }
    if (kind === 'calibration') {
      const discard = numberOrRaw(value('f-discard'));
      if (discard !== undefined) job.discard = discard;
      const list = value('f-d0-values').trim();
      if (list) job.d0_values = list.split(/[\s,;]+/).filter(Boolean).map((x) => numberOrRaw(x));
    }
    if (kind === 'spray' && shown('f-ensemble')) {
      const ensemble = numberOrRaw(value('f-ensemble'));
      if (ensemble !== undefined) job.ensemble = ensemble;
    }
    return job;
  }

  async function submitJob(job, sceneField, what = 'The server refused the job', fieldOverrides = {}) {
    try {
      return await api('/v1/jobs', { method: 'POST', json: job });
    } catch (e) {
      if (e instanceof ApiError && e.status !== 401) showErrors(`${what}: ${e.message}`, e.errors, sceneField, fieldOverrides);
      throw e;
    }
  }

  /// Calibration on the database, then a spray job with the D0 it selected (scripts/pipeline.sh): the
  /// page waits for the calibration while it stays open.
  async function pipeline(scene, sceneField) {
    const calibrationJob = jobOf('calibration', scene);
    const calibrationDuration = numberOrRaw(document.getElementById('f-calibration-duration').value);
    if (calibrationDuration === undefined) delete calibrationJob.duration;
    else calibrationJob.duration = calibrationDuration;
    const calibration = await submitJob(calibrationJob, sceneField, 'The server refused the calibration',
      { '/duration': 'f-calibration-duration' });
    const line = h('p', {}, 'Calibration ', h('a', { href: `#/jobs/${calibration.id}` }, `job ${shortId(calibration.id)}`), ' submitted; waiting for it ');
    const bar = h('progress', { max: 1, value: 0, 'aria-label': 'calibration progress' });
    status.replaceChildren(line, bar);
    for (;;) {
      if (signal.aborted) return;
      const job = await api(`/v1/jobs/${calibration.id}`);
      bar.value = job.progress?.fraction ?? 0;
      if (job.state === 'SUCCEEDED') break;
      if (FINAL.has(job.state)) { status.append(message(`The calibration ended ${job.state}; no spray job submitted.`, 'error')); return; }
      await new Promise((r) => setTimeout(r, POLL_MS));
    }
    const result = await api(`/v1/jobs/${calibration.id}/result`);
    const d0 = result.selected_d0;
    const sprayJob = jobOf('spray', scene);
    delete sprayJob.ensemble;  // not a field of the pipeline
    (sprayJob.scene.rcfd ??= {}).d0 = d0;
    const spray = await submitJob(sprayJob, sceneField, 'The server refused the spray job');
    status.append(h('p', {}, `The calibration selected D0 = ${d0} m²/s; spray `, h('a', { href: `#/jobs/${spray.id}` }, `job ${shortId(spray.id)}`), ' submitted.'));
  }

  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    clearErrors();
    status.replaceChildren();
    submitButton.disabled = true;
    try {
      const { scene, job, field: sceneField } = await sceneOf();
      const kind = kindSelect.value;
      if (job) {
        const made = await submitJob(job, sceneField);
        location.hash = `#/jobs/${made.id}`;
      } else if (kind === 'pipeline') {
        await pipeline(scene, sceneField);
      } else {
        const made = await submitJob(jobOf(kind, scene), sceneField);
        location.hash = `#/jobs/${made.id}`;
      }
    } catch (err) {
      if (err.violations) showErrors('The JSON could not be read', err.violations, 'f-json');
      else if (!(err instanceof ApiError) || err.errors.length === 0) {
        if (!summary.childElementCount) showErrors(errorText(err), [], null);
      }
    } finally {
      submitButton.disabled = false;
    }
  });

  (async () => {
    try {
      const [examples, uploads, dbJobs] = await Promise.all([
        api('/v1/examples'), api('/v1/databases'), api('/v1/jobs?kind=database&page_size=1000')]);
      exampleSelect.replaceChildren(...examples.examples.map((x) => h('option', { value: x.name, title: x.description, selected: x.name === 'quick' }, x.name)));
      const wanted = query.get('database');
      const options = [h('option', { value: '' }, '(none)')];
      for (const d of uploads.databases)
        options.push(h('option', { value: d.id, selected: d.id === wanted }, `upload ${shortId(d.id)} (${d.frames} frames, ${bytes(d.bytes)})`));
      for (const j of dbJobs.jobs.filter((j) => !['FAILED', 'CANCELLED'].includes(j.state)))
        options.push(h('option', { value: j.id, selected: j.id === wanted }, `database job ${shortId(j.id)} (${j.state})`));
      databaseSelect.replaceChildren(...options);
    } catch (e) { status.replaceChildren(message(errorText(e), 'error')); }
  })();
  queueMicrotask(kindChanged);
  return [heading('Submit a job'), form];
}

// ---------------------------------------------------------------- databases

function databasesView(signal) {
  const fileInput = h('input', { id: 'db-file', type: 'file', accept: '.h5,.hdf5,application/x-hdf5', required: true });
  const bar = h('progress', { id: 'upload-progress', max: 1, value: 0, 'aria-label': 'upload progress' });
  const barText = h('span', { class: 'progress-text' }, '');
  const status = h('div', { 'aria-live': 'polite' });
  const button = h('button', { type: 'submit' }, 'Upload');
  const tbody = h('tbody');
  const form = h('form', { class: 'card', novalidate: true },
    h('p', {}, h('label', { for: 'db-file' }, 'Field database (HDF5, docs/formats.md)')), h('p', {}, fileInput),
    h('p', {}, button), h('p', { class: 'progress' }, bar, barText), status);
  form.addEventListener('submit', async (e) => {
    e.preventDefault();
    const file = fileInput.files[0];
    if (!file) { status.replaceChildren(message('Choose a file first.', 'error')); fileInput.focus(); return; }
    button.disabled = true;
    status.replaceChildren(message(`Uploading ${file.name} (${bytes(file.size)})…`));
    try {
      const db = await uploadDatabase(file, (sent, total) => {
        bar.value = total ? sent / total : 0;
        barText.textContent = ` ${percent(bar.value)} of ${bytes(total)}`;
        if (sent >= total) status.replaceChildren(message('Uploaded; the server checks every frame…'));
      });
      status.replaceChildren(message(`Database ${shortId(db.id)} stored: ${db.frames} frames.`));
      await refresh();
    } catch (err) {
      status.replaceChildren(message(errorText(err), 'error'));
    } finally { button.disabled = false; }
  });
  async function refresh() {
    const list = await api('/v1/databases');
    tbody.replaceChildren(...list.databases.map((d) => h('tr', { 'data-database': d.id },
      h('th', { scope: 'row', 'data-label': 'Database' }, h('code', { title: d.id }, shortId(d.id))),
      h('td', { 'data-label': 'Frames' }, String(d.frames)),
      h('td', { 'data-label': 'Size' }, bytes(d.bytes)),
      h('td', { 'data-label': 'Uploaded' }, when(d.created_at)),
      h('td', { 'data-label': '' }, h('a', { href: `#/submit?database=${d.id}` }, 'Use in a job')))));
    if (!list.databases.length) tbody.append(h('tr', {}, h('td', { colspan: 5 }, 'No uploads yet.')));
  }
  refresh().catch((e) => status.replaceChildren(message(errorText(e), 'error')));
  return [heading('Databases'), h('h2', {}, 'Upload'), form, h('h2', {}, 'Uploaded'),
    h('table', { class: 'databases' }, h('thead', {}, h('tr', {}, ['Database', 'Frames', 'Size', 'Uploaded', ''].map((t) => h('th', { scope: 'col' }, t)))), tbody)];
}

// ---------------------------------------------------------------- compare

function compareView(signal, query) {
  const chosen = [query.get('a') || '', query.get('b') || ''];
  const selects = chosen.map((value, i) => h('select', { id: `compare-${i}` }, h('option', { value: '' }, '(choose a spray job)')));
  const out = h('div', { 'aria-live': 'polite' });
  const form = h('form', { class: 'card filters', novalidate: true },
    h('label', { for: 'compare-0' }, 'First job '), selects[0],
    h('label', { for: 'compare-1' }, 'Second job '), selects[1],
    h('button', { type: 'submit' }, 'Compare'));
  form.addEventListener('submit', (e) => {
    e.preventDefault();
    const q = new URLSearchParams();
    if (selects[0].value) q.set('a', selects[0].value);
    if (selects[1].value) q.set('b', selects[1].value);
    location.hash = `#/compare?${q}`;
  });
  (async () => {
    try {
      const list = await api('/v1/jobs?kind=spray&state=SUCCEEDED&page_size=1000');
      selects.forEach((select, i) => {
        for (const j of list.jobs)
          select.append(h('option', { value: j.id, selected: j.id === chosen[i] }, `spray job ${shortId(j.id)}, finished ${when(j.finished_at)}`));
      });
      const ids = chosen.filter(Boolean);
      if (!ids.length) { out.replaceChildren(message('Choose one or two finished spray jobs.')); return; }
      const items = await Promise.all(ids.map(coverageOf));
      out.replaceChildren(coverageSection(items));
    } catch (e) { out.replaceChildren(message(errorText(e), 'error')); }
  })();
  return [heading('Compare coverage'), form, out];
}

// ---------------------------------------------------------------- router

let leave = new AbortController();

function showNav() {
  document.getElementById('nav').hidden = !session.token();
}

function route() {
  leave.abort();
  leave = new AbortController();
  const [path, search = ''] = location.hash.replace(/^#/, '').split('?');
  const query = new URLSearchParams(search);
  showNav();
  let view;
  if (!session.token()) view = signInView();
  else if (/^\/jobs\/[0-9a-f]{32}$/.test(path)) view = jobView(leave.signal, path.slice(6));
  else if (path === '/submit') view = submitView(leave.signal, query);
  else if (path === '/databases') view = databasesView(leave.signal);
  else if (path === '/compare') view = compareView(leave.signal, query);
  else view = jobsView(leave.signal, path === '/jobs' ? query : new URLSearchParams());
  main.replaceChildren(...view);
  for (const a of document.querySelectorAll('#nav a')) {
    if (a.getAttribute('href') === `#${path}`) a.setAttribute('aria-current', 'page');
    else a.removeAttribute('aria-current');
  }
  const h1 = main.querySelector('h1');
  if (h1) {
    document.title = `${h1.textContent} · rcfd`;
    h1.focus();
  }
}

document.getElementById('sign-out').addEventListener('click', () => {
  session.signOut();
  location.hash = '#/signin';
  route();
});
window.addEventListener('rcfd:signed-out', route);
window.addEventListener('hashchange', route);
route();
