// A manual browser check of `janus2d serve` (not run by CI): drives a
// headless Chromium through the DevTools protocol with Node's WebSocket —
// loads the page, reads the status once frames arrive, pauses (the step
// stops), steps once (+1), plays again, drags a body to the right, and
// writes a screenshot.
//
//   janus2d serve pyramid20 --port 8080 &
//   chromium --headless=new --no-sandbox --remote-debugging-port=9333 about:blank &
//   node --experimental-websocket crates/cli/tests/browser/cdp_check.js 9333 http://127.0.0.1:8080/ page.png
//
// The CI test is testbed.test.js (playwright-core), run by .ci/browser-test.
const fs = require("fs");
const [,, debugPort, pageUrl, out] = process.argv;
const sleep = (ms) => new Promise((r) => setTimeout(r, ms));
(async () => {
  let target;
  for (let i = 0; i < 50 && !target; i++) {
    try {
      const list = await (await fetch(`http://127.0.0.1:${debugPort}/json/list`)).json();
      target = list.find((t) => t.type === "page");
    } catch (e) { await sleep(200); }
  }
  const ws = new WebSocket(target.webSocketDebuggerUrl);
  await new Promise((r) => ws.addEventListener("open", r));
  let id = 0; const pending = new Map();
  ws.addEventListener("message", (ev) => { const m = JSON.parse(ev.data); if (m.id && pending.has(m.id)) { pending.get(m.id)(m); pending.delete(m.id); } });
  const call = (method, params = {}) => new Promise((r) => { const i = ++id; pending.set(i, r); ws.send(JSON.stringify({ id: i, method, params })); });
  const evaluate = async (expr) => (await call("Runtime.evaluate", { expression: expr, returnByValue: true })).result.result.value;
  await call("Page.enable");
  await call("Emulation.setDeviceMetricsOverride", { width: 1100, height: 700, deviceScaleFactor: 1, mobile: false });
  await call("Page.navigate", { url: pageUrl });
  await sleep(2500);
  console.log("status:", JSON.stringify(await evaluate("document.getElementById('status').textContent")));
  console.log("scenes:", await evaluate("document.getElementById('scene').options.length"));
  await evaluate("document.getElementById('play').click()");
  await sleep(500);
  const s1 = await evaluate("last && last.step");
  await sleep(500);
  const s2 = await evaluate("last && last.step");
  await evaluate("document.getElementById('step').click()");
  await sleep(500);
  const s3 = await evaluate("last && last.step");
  console.log("paused steps", s1, s2, "after step", s3);
  await evaluate("document.getElementById('play').click()");
  await sleep(800);
  // Drag the last solid polygon (a dynamic body drawn after the ground) 120 px right.
  const centre = `(() => { const ps = last.prims.filter((p) => p[0] === "P"); const p = ps[ps.length - 1];
    let x = 0, y = 0, n = 0; for (let i = 3; i + 1 < p.length; i += 2) { x += p[i]; y += p[i + 1]; n++; }
    const r = view.getBoundingClientRect(); return [sx(x / n) + r.left, sy(y / n) + r.top, x / n]; })()`;
  const [px, py, x0] = await evaluate(centre);
  const mouse = (type, x, y) => call("Input.dispatchMouseEvent", { type, x, y, button: "left", buttons: 1, clickCount: 1 });
  await mouse("mousePressed", px, py);
  for (let k = 1; k <= 6; k++) { await mouse("mouseMoved", px + 20 * k, py); await sleep(100); }
  await sleep(1500);
  const [, , x1] = await evaluate(centre);
  await mouse("mouseReleased", px + 120, py);
  console.log(`dragged body x ${x0.toFixed(2)} -> ${x1.toFixed(2)} m`);
  const shot = await call("Page.captureScreenshot", { format: "png" });
  fs.writeFileSync(out, Buffer.from(shot.result.data, "base64"));
  ws.close(); process.exit(0);
})().catch((e) => { console.error(e); process.exit(1); });
