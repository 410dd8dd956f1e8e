// Screenshots of the page for the docs: a spray job's page and the coverage comparison of two jobs.
// Started by tests/web/test_browser.cpp (WebBrowser.DocsScreenshots, via scripts/web-screenshots.sh)
// with a server whose jobs RCFD_WEB_JOBS names; writes RCFD_WEB_SCREENSHOTS/web-job.png and web-compare.png.
import assert from 'node:assert/strict';
import { join } from 'node:path';
import { launchBrowser, watchForFaults } from './browser.mjs';

const url = process.env.RCFD_WEB_URL;
const token = process.env.RCFD_WEB_TOKEN;
const [first, second] = (process.env.RCFD_WEB_JOBS || '').split(',');
const out = process.env.RCFD_WEB_SCREENSHOTS;
assert.ok(url && token && first && second && out, 'RCFD_WEB_URL, RCFD_WEB_TOKEN, RCFD_WEB_JOBS, RCFD_WEB_SCREENSHOTS');

const context = await launchBrowser({ width: 1280, height: 800 });
try {
  const page = await context.newPage();
  const faults = watchForFaults(page);
  await page.goto(`${url}/`);
  await page.getByLabel('Token', { exact: true }).fill(token);
  await page.getByRole('button', { name: 'Sign in' }).click();
  await page.getByRole('heading', { name: 'Jobs' }).waitFor();

  await page.goto(`${url}/#/jobs/${first}`);
  await page.locator('section.coverage svg.chart').waitFor();
  await page.waitForFunction(() => [...document.querySelectorAll('img[data-figure]')].every((i) => i.naturalWidth > 0));
  await page.screenshot({ path: join(out, 'web-job.png'), fullPage: true });

  await page.goto(`${url}/#/compare?a=${first}&b=${second}`);
  await page.locator('section.coverage svg.chart path.steps').nth(1).waitFor();
  await page.screenshot({ path: join(out, 'web-compare.png'), fullPage: true });
  assert.deepEqual(faults, []);
  console.log(`wrote ${join(out, 'web-job.png')} and ${join(out, 'web-compare.png')}`);
} finally {
  await context.close();
}
