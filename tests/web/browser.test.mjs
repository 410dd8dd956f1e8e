// The web page in a real browser against a real rcfd-server on loopback (started by
// tests/web/test_browser.cpp, which passes its address, token and a small field database in RCFD_WEB_*):
// sign in, upload the database with a progress bar, submit a small spray job (two ensemble members) on
// it, watch it finish, see its coverage plot with the ensemble band and its figures, download the
// coverage CSV, cancel a second job, see a validation error beside its field, read the job list at a
// phone's width, and chain a calibration and a spray job.
import assert from 'node:assert/strict';
import { writeFileSync } from 'node:fs';
import { join } from 'node:path';
import { after, before, test } from 'node:test';
import { launchBrowser, watchForFaults } from './browser.mjs';

const url = process.env.RCFD_WEB_URL;
const token = process.env.RCFD_WEB_TOKEN;
const database = process.env.RCFD_WEB_DATABASE;
const downloads = process.env.RCFD_WEB_DOWNLOADS;
assert.ok(url && token && database && downloads, 'RCFD_WEB_URL, RCFD_WEB_TOKEN, RCFD_WEB_DATABASE, RCFD_WEB_DOWNLOADS');

let context, page, faults;
let databaseId, sprayId;

before(async () => {
  context = await launchBrowser();
  page = await context.newPage();
  faults = watchForFaults(page);
});
after(async () => { await context?.close(); });

test('a wrong token is refused; the right one, typed and sent with Enter, signs in', async () => {
  await page.goto(`${url}/`);
  await page.getByLabel('Token', { exact: true }).fill('not-the-token');
  await page.getByRole('button', { name: 'Sign in' }).click();
  await page.getByText('The server does not know this token.').waitFor();
  const field = page.getByLabel('Token', { exact: true });
  await field.fill('');
  await field.focus();
  await page.keyboard.type(token);
  await page.keyboard.press('Enter');
  await page.getByRole('heading', { name: 'Jobs' }).waitFor();
  assert.match(page.url(), /#\/jobs$/);
  assert.ok(!page.url().includes(token), 'the token is not in the URL');
  assert.equal(await page.evaluate(() => sessionStorage.getItem('rcfd-token')), token);
  assert.equal(await page.evaluate(() => localStorage.length), 0);
});

test('a database uploads with a progress bar and is listed', async () => {
  await page.getByRole('link', { name: 'Databases' }).click();
  await page.getByLabel(/Field database/).setInputFiles(database);
  await page.getByRole('button', { name: 'Upload' }).click();
  await page.getByText(/Database [0-9a-f]{8} stored: \d+ frames/).waitFor({ timeout: 60_000 });
  assert.equal(await page.locator('#upload-progress').evaluate((p) => p.value), 1);
  databaseId = await page.locator('tr[data-database]').first().getAttribute('data-database');
  assert.match(databaseId, /^[0-9a-f]{32}$/);
});

async function submitSpray(duration, ensemble = '') {
  await page.goto(`${url}/#/submit?database=${databaseId}`);
  await page.getByLabel('Example scene', { exact: true }).selectOption('quick');
  await page.getByLabel('Kind', { exact: true }).selectOption('spray');
  await page.locator(`#f-database option[value="${databaseId}"]`).waitFor({ state: 'attached' });
  await page.getByLabel('Database', { exact: true }).selectOption(databaseId);
  await page.getByLabel('Duration [s]', { exact: true }).fill(String(duration));
  await page.getByLabel('Tracers', { exact: true }).fill('200');
  await page.getByLabel('Ensemble members', { exact: true }).fill(ensemble);
  await page.getByRole('button', { name: 'Submit' }).click();
  await page.waitForURL(/#\/jobs\/[0-9a-f]{32}$/);
  return page.url().split('/').pop();
}

test('a small spray job with two ensemble members finishes and shows its coverage with the band', async () => {
  sprayId = await submitSpray(0.25, '2');
  await page.getByRole('heading', { name: /^Spray job/ }).waitFor();
  await page.locator('.state', { hasText: 'SUCCEEDED' }).waitFor({ timeout: 180_000 });
  const chart = page.locator('section.coverage svg.chart');
  await chart.waitFor();
  assert.ok(await chart.locator('rect.bar').count() >= 10, 'a bar per coverage bin');
  assert.equal(await chart.locator('rect.band').count(), await chart.locator('rect.bar').count(), 'the ensemble band');
  const yTicks = await chart.locator('text.tick-y').allTextContents();
  for (const t of yTicks) assert.match(t, /^\d+(\.\d*[05]?)?$|^0$/, `round tick ${t}`);
  const stats = page.locator('table.stats tbody tr');
  assert.equal(await stats.count(), 1);
  assert.match(await stats.locator('td').nth(1).textContent(), /^\d(\.\d+)?(e-\d+)?$/, 'the median');
  // The solver's own figures are shown, fetched with the token into blob: URLs.
  const figure = page.locator('img[data-figure="coverage.svg"]');
  await figure.waitFor();
  await page.waitForFunction(() => document.querySelector('img[data-figure="coverage.svg"]')?.naturalWidth > 0);
  assert.match(await figure.getAttribute('src'), /^blob:/);
  assert.ok((await page.locator('section pre.json').first().textContent()).includes('"kind": "spray"'), 'the job file');
});

test('the coverage CSV downloads', async () => {
  const [download] = await Promise.all([
    page.waitForEvent('download'),
    page.getByRole('button', { name: 'Coverage CSV' }).click(),
  ]);
  const path = join(downloads, download.suggestedFilename());
  await download.saveAs(path);
  assert.match(download.suggestedFilename(), /^coverage-[0-9a-f]{8}\.csv$/);
  writeFileSync(join(downloads, 'spray-job-id'), sprayId);
});

test('a second job is cancelled from its page', async () => {
  const id = await submitSpray(600);
  assert.notEqual(id, sprayId);
  const cancel = page.getByRole('button', { name: 'Cancel job' });
  await cancel.waitFor();
  await cancel.click();
  await page.locator('.state', { hasText: /^CANCELLED$/ }).waitFor({ timeout: 90_000 });
  assert.equal(await page.getByRole('button', { name: 'Cancel job' }).count(), 0);
  await page.getByRole('button', { name: 'Retry' }).waitFor();
});

test('a validation error of the server is shown beside the field it names', async () => {
  await page.goto(`${url}/#/submit?database=${databaseId}`);
  await page.getByLabel('Kind', { exact: true }).selectOption('spray');
  await page.getByLabel('Duration [s]', { exact: true }).fill('-1');
  await page.getByRole('button', { name: 'Submit' }).click();
  const error = page.locator('#f-duration-error');
  await error.waitFor({ state: 'visible' });
  assert.match(await error.textContent(), /-1/);
  assert.equal(await page.getByLabel('Duration [s]', { exact: true }).getAttribute('aria-invalid'), 'true');
  assert.match(await page.getByLabel('Duration [s]', { exact: true }).getAttribute('aria-describedby'), /f-duration-error/);
  assert.match(await page.locator('#error-summary').textContent(), /\/duration/);
  assert.match(page.url(), /#\/submit/);
  // A pasted job's violations are listed by their pointer.
  await page.getByLabel(/Paste or upload/).check();
  await page.getByLabel('Scene or job JSON', { exact: true }).fill(JSON.stringify({ kind: 'teleport', scene: {} }));
  await page.getByRole('button', { name: 'Submit' }).click();
  await page.locator('#error-summary li', { hasText: '/kind' }).waitFor();
});

test('the job list shows kind, state, progress and ETA, also at a phone\'s width', async () => {
  await page.goto(`${url}/#/jobs`);
  const row = page.locator(`tr[data-job="${sprayId}"]`);
  await row.waitFor();
  assert.equal(await row.locator('td[data-label="Kind"]').textContent(), 'spray');
  assert.equal(await row.locator('progress').evaluate((p) => p.value), 1);
  assert.equal(await page.locator('tbody tr[data-job]').count(), 2);
  await page.setViewportSize({ width: 390, height: 844 });
  await page.waitForTimeout(200);
  const overflow = await page.evaluate(() => document.documentElement.scrollWidth - window.innerWidth);
  assert.ok(overflow <= 0, `no horizontal scrolling at 390 px (${overflow} px too wide)`);
  await page.setViewportSize({ width: 1280, height: 800 });
});

test('calibration, then spray: the page submits the spray job with the D0 the calibration selected', async () => {
  await page.goto(`${url}/#/submit?database=${databaseId}`);
  await page.getByLabel('Kind', { exact: true }).selectOption('pipeline');
  await page.locator(`#f-database option[value="${databaseId}"]`).waitFor({ state: 'attached' });
  await page.getByLabel('Database', { exact: true }).selectOption(databaseId);
  await page.getByLabel('Duration [s]', { exact: true }).fill('0.25');
  await page.getByLabel('Calibration duration [s]', { exact: true }).fill('0.25');
  await page.getByLabel('Discard [s]', { exact: true }).fill('0');
  await page.getByLabel('D0 values [m²/s]', { exact: true }).fill('0, 1e-4');
  await page.getByLabel('Tracers', { exact: true }).fill('200');
  await page.getByRole('button', { name: 'Submit' }).click();
  const done = page.getByText(/The calibration selected D0 = \S+ m²\/s; spray/);
  await done.waitFor({ timeout: 180_000 });
  const link = done.getByRole('link');
  assert.match(await link.getAttribute('href'), /^#\/jobs\/[0-9a-f]{32}$/);
});

test('no uncaught error and no Content-Security-Policy violation happened', () => {
  assert.deepEqual(faults, []);
});
