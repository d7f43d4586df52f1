// The preview page in a real browser: Debian's headless Chromium, driven by
// playwright-core, against a running obscurad (tests/e2e/browser.sh starts
// it and passes its URL).
//
//   OBSCURAD_URL=http://127.0.0.1:PORT CAM='fov_y=50&...' node tests/browser/preview.test.mjs
//
// Loads the page, posts two frames to a stream and sees the image change
// (pixels of a screenshot), moves a slider and sees the re-run request
// carry the parameter, switches to the split view, drops an EXR on the page;
// the controls show each frame's own parameters; a deep frame shows its
// front layer's AO and says it is deep.
import { chromium } from 'playwright-core';
import { readFileSync } from 'node:fs';
import { inflateSync } from 'node:zlib';

const BASE = process.env.OBSCURAD_URL;
const CAM = process.env.CAM || '';
const EXR = process.env.EXR || 'tests/data/room_small.exr';
const DEEP = process.env.DEEP || 'tests/data/deep_small.exr';
const CHROMIUM = process.env.CHROMIUM || '/usr/bin/chromium';
const TIMEOUT = 20000;

let passed = 0, failed = 0;
function check(name, cond, detail) {
  if (cond) { passed++; console.log('  ok   ' + name); }
  else { failed++; console.log('  FAIL ' + name + (detail ? ' (' + detail + ')' : '')); }
}

// Mean of R, G, B over a PNG (8-bit, RGB or RGBA, not interlaced: what
// Chromium's screenshots are), optionally over the columns [x0, x1) only.
function pngMean(buf, x0 = 0, x1 = Infinity) {
  let pos = 8, w = 0, h = 0, ch = 0;
  const idat = [];
  while (pos < buf.length) {
    const len = buf.readUInt32BE(pos), type = buf.toString('ascii', pos + 4, pos + 8);
    const data = buf.subarray(pos + 8, pos + 8 + len);
    if (type === 'IHDR') {
      w = data.readUInt32BE(0); h = data.readUInt32BE(4);
      if (data[8] !== 8 || data[12] !== 0) throw new Error('unexpected PNG layout');
      ch = { 2: 3, 6: 4 }[data[9]];
    } else if (type === 'IDAT') idat.push(data);
    pos += 12 + len;
  }
  const raw = inflateSync(Buffer.concat(idat));
  const stride = w * ch, out = Buffer.alloc(stride * h);
  for (let y = 0; y < h; y++) {
    const f = raw[y * (stride + 1)], line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; i++) {
      const a = i >= ch ? out[y * stride + i - ch] : 0, b = y ? out[(y - 1) * stride + i] : 0;
      const c = y && i >= ch ? out[(y - 1) * stride + i - ch] : 0;
      let p = line[i];
      if (f === 1) p += a;
      else if (f === 2) p += b;
      else if (f === 3) p += (a + b) >> 1;
      else if (f === 4) {
        const q = a + b - c, pa = Math.abs(q - a), pb = Math.abs(q - b), pc = Math.abs(q - c);
        p += pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      out[y * stride + i] = p & 255;
    }
  }
  let sum = 0, n = 0;
  for (let y = 0; y < h; y++)
    for (let x = Math.max(0, x0); x < Math.min(w, x1); x++) {
      const o = y * stride + x * ch;
      sum += out[o] + out[o + 1] + out[o + 2];
      n += 3;
    }
  return { mean: sum / n, width: w, height: h };
}

async function postFrame(stream, query) {
  const resp = await fetch(`${BASE}/v1/streams/${stream}/frames?${query}`, {
    method: 'POST', headers: { 'Content-Type': 'image/x-exr' }, body: readFileSync(EXR),
  });
  await resp.arrayBuffer();
  return resp;
}

// Waits until the page shows frame `n` with its image(s) loaded.
async function shown(page, n, stream) {
  await page.waitForFunction(([n, stream]) => {
    const st = document.getElementById('stage'), img = document.getElementById('img-base');
    const info = document.getElementById('info-frame').textContent;
    return !st.hidden && st.dataset.frame === String(n) && info.includes('(' + stream + ')') &&
      img.complete && img.naturalWidth > 0;
  }, [n, stream], { timeout: TIMEOUT });
}

const browser = await chromium.launch({
  executablePath: CHROMIUM,
  args: ['--no-sandbox', '--disable-gpu', '--disable-dev-shm-usage'],
});
const t0 = Date.now();
try {
  const page = await browser.newPage({ viewport: { width: 1100, height: 700 } });
  const errors = [];
  page.on('pageerror', (e) => errors.push(e.message));
  const requests = [];
  page.on('request', (r) => requests.push(r.method() + ' ' + r.url()));

  await page.goto(BASE + '/');
  await page.waitForSelector('#param-radius input[type=range]', { timeout: TIMEOUT });
  check('page loads; parameter controls generated from /v1/params',
    await page.locator('#params .param').count() >= 10 &&
    await page.locator('#param-samples select option').count() === 5);
  const radiusDefault = await page.locator('#param-radius input[type=number]').inputValue();
  check('slider defaults come from the table (radius ' + radiusDefault + ')', radiusDefault === '0.5');

  await page.locator('input[name=view][value=ao]').check();
  let resp = await postFrame('shot', CAM + '&radius=0.1');
  check('frame 1 posted to stream shot: ' + resp.status, resp.status === 200 && resp.headers.get('x-obscura-frame') === '1');
  await shown(page, 1, 'shot');
  const m1 = pngMean(await page.locator('#img-base').screenshot());
  resp = await postFrame('shot', CAM + '&radius=3');
  check('frame 2 posted: ' + resp.status, resp.status === 200 && resp.headers.get('x-obscura-frame') === '2');
  await shown(page, 2, 'shot');
  const m2 = pngMean(await page.locator('#img-base').screenshot());
  check(`the image updated to frame 2 (mean grey ${m1.mean.toFixed(1)} -> ${m2.mean.toFixed(1)}, ${m2.width}x${m2.height})`,
    Math.abs(m1.mean - m2.mean) > 15 && m2.width > 300);
  check('the controls show frame 2\'s own parameters (radius 3, fov_y 50, near 0.05), not the table\'s defaults',
    await page.locator('#param-radius input[type=number]').inputValue() === '3' &&
    await page.locator('#param-fov_y input[type=number]').inputValue() === '50' &&
    await page.locator('#param-near input[type=number]').inputValue() === '0.05' &&
    !(await page.locator('#param-radius').getAttribute('class')).includes('changed'));
  check('the object-mask selectors are text fields suggesting the frame\'s names (datalist objects)',
    await page.locator('#param-receivers input[type=text]').getAttribute('list') === 'objects' &&
    await page.locator('#param-occluders input[type=text]').getAttribute('maxlength') === '1023' &&
    await page.locator('#param-self_only select option').count() === 2);
  check('frame counter, resolution and timings shown',
    (await page.locator('#info-frame').textContent()).startsWith('2') &&
    (await page.locator('#info-size').textContent()) === '320 × 240' &&
    /ms$/.test(await page.locator('#info-gl').textContent()));

  // move the radius slider with the keyboard: the frame is re-run with it
  const before = requests.length;
  const rerun = page.waitForResponse((r) => /\/v1\/streams\/shot\/frames\/2\?.*radius=/.test(r.url()), { timeout: TIMEOUT });
  await page.locator('#param-radius input[type=range]').focus();
  for (let i = 0; i < 40; i++) await page.keyboard.press('ArrowRight');
  const rr = await rerun;
  const radius = Number(new URL(rr.url()).searchParams.get('radius'));
  check(`moving the slider re-runs the frame with radius=${radius} (${rr.status()})`,
    rr.status() === 200 && radius > 0.5 && requests.slice(before).some((u) => u.includes('radius=')));
  await page.waitForFunction(() => /re-run with radius=/.test(document.getElementById('status').textContent),
    null, { timeout: TIMEOUT });

  // split view: colour | composite with a divider
  await page.locator('#param-radius button').click(); // back to the default
  await page.locator('input[name=view][value=split]').check();
  await page.waitForFunction(() => {
    const top = document.getElementById('img-top');
    return !top.hidden && top.complete && top.naturalWidth > 0 && !document.getElementById('divider').hidden;
  }, null, { timeout: TIMEOUT });
  const colorReq = requests.some((u) => /frames\/2\?output=color&format=png&exposure=0/.test(u));
  check('split view: colour input and composite, divider shown', colorReq);
  const ex = page.waitForResponse((r) => /output=color.*exposure=2/.test(r.url()), { timeout: TIMEOUT });
  await page.locator('#exposure').focus();
  for (let i = 0; i < 8; i++) await page.keyboard.press('ArrowRight');
  check('exposure control asks for tone-mapped colour (exposure=2)', (await ex).status() === 200);

  // drop an EXR (no camera in its header: set fov_y first)
  await page.locator('#param-fov_y input[type=number]').fill('50');
  await page.locator('#param-fov_y input[type=number]').dispatchEvent('change');
  const b64 = readFileSync(EXR).toString('base64');
  const dt = await page.evaluateHandle((b64) => {
    const bytes = Uint8Array.from(atob(b64), (c) => c.charCodeAt(0));
    const d = new DataTransfer();
    d.items.add(new File([bytes], 'dropped.exr', { type: 'image/x-exr' }));
    return d;
  }, b64);
  const dropPost = page.waitForResponse((r) => r.request().method() === 'POST' && /\/v1\/streams\/drop\/frames\?/.test(r.url()),
    { timeout: TIMEOUT });
  await page.dispatchEvent('#viewer', 'drop', { dataTransfer: dt });
  const dp = await dropPost;
  check(`dropped EXR posted with the page's parameters (${dp.status()})`,
    dp.status() === 200 && new URL(dp.url()).searchParams.get('fov_y') === '50');
  await shown(page, 1, 'drop');
  check('the dropped frame is shown (stream drop selected)', (await page.locator('#stream').inputValue()) === 'drop');

  // a deep frame: its front layer's AO, said to be deep; the camera of its file in the controls
  const front = page.waitForResponse((r) => /\/v1\/streams\/drop\/frames\/2\?output=ao_front&format=png/.test(r.url()),
    { timeout: TIMEOUT });
  resp = await fetch(`${BASE}/v1/streams/drop/frames?deep_layers=3`, {
    method: 'POST', headers: { 'Content-Type': 'image/x-exr' }, body: readFileSync(DEEP),
  });
  await resp.arrayBuffer();
  check('deep frame posted to stream drop: ' + resp.status, resp.status === 200);
  const fr = await front;
  await shown(page, 2, 'drop');
  check(`deep frame shown: its front layer's AO (${fr.status()}), said to be deep, fov_y from its file (40)`,
    fr.status() === 200 && (await page.locator('#info-kind').textContent()).startsWith('deep') &&
    await page.locator('#param-fov_y input[type=number]').inputValue() === '40');

  const shot = await page.screenshot();
  if (process.env.SCREENSHOT) (await import('node:fs')).writeFileSync(process.env.SCREENSHOT, shot);
  check('no JavaScript errors' + (errors.length ? ': ' + errors.join('; ') : ''), errors.length === 0);
} catch (e) {
  check('browser run: ' + e.message.split('\n')[0], false);
} finally {
  await browser.close();
}
console.log(`  (${((Date.now() - t0) / 1000).toFixed(1)} s in the browser)`);
console.log(`browser: ${passed} passed, ${failed} failed`);
process.exit(failed ? 1 : 0);
