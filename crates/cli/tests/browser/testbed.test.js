// `janus2d serve` end to end in a real browser: headless Chromium (Debian's
// `chromium`, not Playwright's download) driven by playwright-core. Loads
// the page, sees frames arrive, pauses (the step holds), steps once (+1),
// plays again, drags the box to the right with the mouse and checks in the
// next frames that it moved, then writes a screenshot. Then: the keys
// (space pauses and plays, s steps, r resets); with scripts off the page
// still shows the scene (the server's inline SVG); and every built-in
// scene in the picker draws bodies inside the canvas, with screenshots of
// tumbler, portal_drop and large_pyramid beside the first one
// (testbed-NAME.png, testbed-noscript-tumbler.png).
//
//   janus2d serve single_box --port 8080 &
//   npm ci && node testbed.test.js http://127.0.0.1:8080/ page.png
//
// `.ci/browser-test` does all of that. CHROMIUM overrides the browser's
// path (default /usr/bin/chromium). Exit status 0: every check passed.
"use strict";
const { chromium } = require("playwright-core");

const [, , url = "http://127.0.0.1:8080/", shot = "testbed.png"] = process.argv;
const executablePath = process.env.CHROMIUM || "/usr/bin/chromium";

let failures = 0;
function check(ok, what) {
  console.log(`${ok ? "ok  " : "FAIL"} ${what}`);
  if (!ok) failures++;
}

(async () => {
  const browser = await chromium.launch({
    executablePath,
    headless: true,
    args: ["--no-sandbox", "--headless=new", "--disable-gpu", "--disable-dev-shm-usage"],
  });
  try {
    const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
    page.on("pageerror", (e) => { console.log(`FAIL page error: ${e.message}`); failures++; });
    await page.goto(url);
    const frames = () => page.evaluate(() => window.janus.frames());
    const last = () => page.evaluate(() => {
      const f = window.janus.last();
      return f && { step: f.step, running: f.running, bodies: f.bodies };
    });
    // Waits until `pred(last frame)` holds (or the time is up) and returns that frame.
    const until = async (pred, ms = 5000) => {
      const end = Date.now() + ms;
      let f = await last();
      while (!(f && pred(f)) && Date.now() < end) {
        await page.waitForTimeout(50);
        f = await last();
      }
      return f;
    };

    // 1. Frames arrive, and keep arriving while it runs.
    await page.waitForFunction(() => window.janus && window.janus.frames() >= 5, null, { timeout: 15000 });
    const n0 = await frames(), a = await last();
    await page.waitForTimeout(1000);
    const n1 = await frames(), b = await last();
    check(n1 > n0, `frames arrive: ${n0} -> ${n1} in 1 s`);
    check(b.step > a.step, `the step counter runs: ${a.step} -> ${b.step}`);
    check(b.bodies >= 2, `bodies in the scene: ${b.bodies}`);
    const scenes = await page.locator("#scene option").count();
    check(scenes > 10, `scene picker lists ${scenes} scenes`);
    const picked = await page.inputValue("#scene");
    check(picked === "single_box", `the served scene is picked: ${picked}`);
    // Status, chart and help sit beside the stage, not over it.
    const [vr, sr] = await page.evaluate(() => [window.janus.viewBox(), (() => { const r = document.getElementById("side").getBoundingClientRect(); return [r.left, r.top, r.right, r.bottom]; })()]);
    check(sr[0] >= vr[2] - 0.5, `the side panel (x ${sr[0]}) is right of the stage (to ${vr[2]})`);
    check((await page.locator("#legend span").count()) === 5, "the chart has a legend of 5 stages");

    // 2. Pause: the step holds.
    await page.click("#play");
    const p = await until((f) => !f.running);
    check(p && !p.running, "paused");
    const s1 = (await last()).step;
    await page.waitForTimeout(700);
    const s2 = (await last()).step;
    check(s2 === s1, `paused, the step holds: ${s1} -> ${s2}`);

    // 3. Step once: +1, still paused.
    await page.click("#step");
    const s = await until((f) => f.step !== s1);
    check(s.step === s1 + 1 && !s.running, `one step: ${s1} -> ${s.step}, paused ${!s.running}`);

    // 4. Play again, let the box land, then drag it 150 px to the right.
    await page.click("#play");
    await until((f) => f.running);
    await page.waitForTimeout(1500);
    // The dynamic body: the smallest filled polygon (the ground is far larger).
    const box = () => page.evaluate(() => {
      let best = null;
      for (const p of window.janus.last().prims) {
        if (p[0] !== "P") continue;
        let x = 0, y = 0, n = 0, x0 = Infinity, x1 = -Infinity, y0 = Infinity, y1 = -Infinity;
        for (let i = 3; i + 1 < p.length; i += 2) {
          x += p[i]; y += p[i + 1]; n++;
          x0 = Math.min(x0, p[i]); x1 = Math.max(x1, p[i]); y0 = Math.min(y0, p[i + 1]); y1 = Math.max(y1, p[i + 1]);
        }
        const area = (x1 - x0) * (y1 - y0);
        if (!best || area < best.area) best = { area, x: x / n, y: y / n };
      }
      return best && { ...best, page: window.janus.toPage(best.x, best.y), scale: window.janus.scale() };
    });
    const before = await box();
    check(before !== null, `a body to drag at (${before.x.toFixed(2)}, ${before.y.toFixed(2)}) m`);
    const push = 150, target = push / before.scale; // px, m
    const [px, py] = before.page;
    await page.mouse.move(px, py);
    await page.mouse.down();
    for (let k = 1; k <= 10; k++) {
      await page.mouse.move(px + (push * k) / 10, py);
      await page.waitForTimeout(50);
    }
    await page.waitForTimeout(1500);
    const after = await box();
    await page.mouse.up();
    const moved = after.x - before.x;
    check(moved > 0.5 * target, `dragged ${target.toFixed(2)} m right: x ${before.x.toFixed(2)} -> ${after.x.toFixed(2)} m (moved ${moved.toFixed(2)} m, need > ${(0.5 * target).toFixed(2)})`);
    const still = await last();
    check(still.running, `running after the drag (step ${still.step})`);

    await page.screenshot({ path: shot });
    console.log(`screenshot: ${shot}`);

    // 5. Keys: space pauses and plays, s steps, r resets.
    await page.mouse.click(5, 5); // focus off any control
    await page.keyboard.press(" ");
    const kp = await until((f) => !f.running);
    check(kp && !kp.running, "space pauses");
    const k1 = (await last()).step;
    await page.keyboard.press("s");
    const ks = await until((f) => f.step !== k1);
    check(ks.step === k1 + 1, `s steps once: ${k1} -> ${ks.step}`);
    await page.keyboard.press("r");
    const kr = await until((f) => f.step === 0);
    check(kr && kr.step === 0, `r resets: step ${kr && kr.step}`);
    await page.keyboard.press(" ");
    const kg = await until((f) => f.running && f.step > 0);
    check(kg && kg.running, "space plays again");
    check(await page.locator("#keys").isVisible(), "the keys are shown on the page");

    // 6. Scripts off: the server's first frame shows the scene.
    const dir = require("path").dirname(shot);
    const noScript = await browser.newContext({ javaScriptEnabled: false, viewport: { width: 1100, height: 700 } });
    const sp = await noScript.newPage();
    await sp.goto(url + "?scene=tumbler");
    const polys = await sp.locator("#still svg polygon").count();
    check(polys > 2000, `without scripts the page shows tumbler's ${polys} polygons`);
    check((await sp.inputValue("#scene")) === "tumbler", "and picks tumbler");
    await sp.screenshot({ path: `${dir}/testbed-noscript-tumbler.png` });
    await noScript.close();

    // 7. Every built-in scene in the picker draws bodies inside the canvas.
    const names = await page.locator("#scene option").evaluateAll((os) => os.map((o) => o.value));
    const SHOTS = new Set(["tumbler", "portal_drop", "large_pyramid"]);
    const walk = Date.now();
    for (const name of names) {
      await page.selectOption("#scene", name);
      const ok = await page.waitForFunction(
        (n) => window.janus.scene() === n && window.janus.sceneFrames() >= 1, name, { timeout: 20000 },
      ).then(() => true, () => false);
      if (!ok) { check(false, `${name}: no frame`); continue; }
      const r = await page.evaluate(() => {
        const f = window.janus.last(), [l, t, rr, b] = window.janus.viewBox();
        let bodies = 0, out = 0, lines = 0;
        for (const p of f.prims) {
          if (p[0] === "L") lines++;
          if (!["P", "C", "K"].includes(p[0])) continue;
          bodies++;
          const pts = p[0] === "P" ? p.slice(3) : p[0] === "C" ? p.slice(2, 4) : p.slice(2, 6);
          for (let i = 0; i + 1 < pts.length; i += 2) {
            const [x, y] = window.janus.toPage(pts[i], pts[i + 1]);
            if (x < l - 1 || x > rr + 1 || y < t - 1 || y > b + 1) { out++; break; }
          }
        }
        return { bodies, out, lines, lit: window.janus.litPixels() };
      });
      // Shapes drawn (the bridge's planks have none: its joints are drawn),
      // pixels lit, and every shape inside the view at the first frame
      // but in rain, whose ragdolls spawn above the first frame's view
      // (`serve rain --fit grow` follows them).
      const drawn = r.bodies > 0 || (name === "bridge" && r.lines > 0);
      const inside = r.out === 0 || name === "rain";
      check(drawn && r.lit > 20 && inside, `${name}: ${r.bodies} shapes and ${r.lines} lines drawn, ${r.lit} lit samples, ${r.out} shapes outside the view`);
      if (SHOTS.has(name)) {
        if (name === "tumbler") await page.waitForTimeout(1500); // the drum turned a little
        await page.screenshot({ path: `${dir}/testbed-${name}.png` });
        console.log(`screenshot: ${dir}/testbed-${name}.png`);
      }
    }
    console.log(`walked ${names.length} scenes in ${((Date.now() - walk) / 1000).toFixed(1)} s`);
  } finally {
    await browser.close();
  }
  if (failures > 0) {
    console.log(`${failures} check(s) failed`);
    process.exit(1);
  }
  console.log("all checks passed");
})().catch((e) => {
  console.error(e);
  process.exit(1);
});
