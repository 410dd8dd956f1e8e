// Starts Debian's chromium headless through playwright-core (no browser download: the system's
// executable), with a fresh profile and without any network use of its own: the machine's network may
// be closed, and a test must talk to its loopback server only.
import { mkdtempSync, rmSync } from 'node:fs';
import { tmpdir } from 'node:os';
import { join } from 'node:path';
import { chromium } from 'playwright-core';

export const CHROMIUM = process.env.RCFD_CHROMIUM || '/usr/bin/chromium';

export async function launchBrowser({ width = 1280, height = 800 } = {}) {
  const profile = mkdtempSync(join(tmpdir(), 'rcfd-web-chromium-'));
  const context = await chromium.launchPersistentContext(profile, {
    executablePath: CHROMIUM,
    headless: true,
    acceptDownloads: true,
    viewport: { width, height },
    args: ['--headless', '--no-sandbox', '--disable-gpu', '--disable-quic', '--no-first-run',
      '--disable-background-networking', '--disable-component-update', '--disable-sync'],
  });
  // The profile goes once the browser has exited (not on the context's close event, while chromium
  // may still write to it).
  const close = context.close.bind(context);
  context.close = async (...args) => {
    await close(...args);
    rmSync(profile, { recursive: true, force: true, maxRetries: 5, retryDelay: 100 });
  };
  return context;
}

/// Collects what must not happen on the page: uncaught errors and Content-Security-Policy violations.
export function watchForFaults(page) {
  const faults = [];
  page.on('pageerror', (e) => faults.push(`uncaught: ${e.message}`));
  page.on('console', (m) => {
    if (m.type() === 'error' && /Content.Security.Policy|Refused to/i.test(m.text())) faults.push(`CSP: ${m.text()}`);
  });
  return faults;
}
