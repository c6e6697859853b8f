// What every browser test shares: Debian's Chromium (TRILUX_BROWSER names
// another), headless, with software WebGL through SwiftShader, and none of
// its background traffic.
import { chromium } from 'playwright-core';

export function launch() {
  return chromium.launch({
    executablePath: process.env.TRILUX_BROWSER || '/usr/bin/chromium',
    args: ['--headless', '--no-sandbox', '--enable-unsafe-swiftshader', '--use-angle=swiftshader-webgl',
      '--disable-background-networking', '--disable-component-update', '--disable-sync', '--no-first-run'],
  });
}

// An 800 × 600 page of an app at `url`, its console errors (and uncaught
// exceptions) collected in `errors`. The page's CSP forbids eval, which
// Playwright's argument passing needs: the page bypasses it.
export async function openPage(browser, errors) {
  const page = await browser.newPage({ viewport: { width: 800, height: 600 }, bypassCSP: true });
  page.on('console', (m) => { if (m.type() === 'error') errors.push(m.text()); });
  page.on('pageerror', (e) => errors.push('pageerror: ' + e.message));
  return page;
}
