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
