// Opens the built page (web/dist) in the system's headless Chromium, on its software WebGPU
// adapter (SwiftShader), and checks what it draws from screenshots. The pixel checks here share
// no code with the page: they classify screenshot pixels by colour only.
//
//   node --test page.test.mjs        (after `bash web/build.sh`; CHROMIUM=path overrides the browser)
import { test, before, after } from 'node:test';
import assert from 'node:assert/strict';
import fs from 'node:fs';
import http from 'node:http';
import os from 'node:os';
import path from 'node:path';
import zlib from 'node:zlib';
import { fileURLToPath } from 'node:url';
import puppeteer from 'puppeteer-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const dist = path.resolve(here, '../dist');
const output = path.resolve(here, 'output');
const chromium = process.env.CHROMIUM || '/usr/bin/chromium';
// A green no other part of the scene has: the bluish grey background and the skin-toned body.
const FUR_HEX = '#30c040';
// SwiftShader draws the fur on the CPU: a small canvas (470 x 400 beside the 250 px panel) keeps
// a frame near a second on a loaded 2-core machine.
const VIEWPORT = { width: 720, height: 400, deviceScaleFactor: 1 };
// pelt render's default bunny from the page's camera on this canvas (crates/pelt-web/tests/look.rs
// keeps it so): the page must show the same background and fur colour.
const LOOK = JSON.parse(fs.readFileSync(path.join(here, 'look.json'), 'utf8'));

// WebGPU on SwiftShader, with the compositor on SwiftShader too. Without a GPU, headless Chromium
// composites in software, which has no shared image for a WebGPU canvas's swap chain ("Could not
// find SharedImageBackingFactory ... WebgpuSwapChainTexture" on its stderr): the first present
// fails and loses the device's instance, and the page never shows a frame. GPU compositing on
// ANGLE's SwiftShader with Vulkan (SwiftShader's) gives the canvas its shared images.
const WEBGPU_ARGS = ['--enable-unsafe-webgpu', '--enable-features=Vulkan', '--use-vulkan=swiftshader',
  '--use-angle=swiftshader'];

const types = { '.html': 'text/html', '.js': 'text/javascript', '.wasm': 'application/wasm' };
let server;
let origin;
let browser;

before(async () => {
  assert.ok(fs.existsSync(path.join(dist, 'index.html')), 'web/dist is missing: run bash web/build.sh first');
  fs.mkdirSync(output, { recursive: true });
  server = http.createServer((request, response) => {
    const name = decodeURIComponent(new URL(request.url, 'http://x').pathname);
    const file = path.join(dist, name === '/' ? 'index.html' : name);
    if (!file.startsWith(dist) || !fs.existsSync(file)) {
      response.writeHead(404).end();
      return;
    }
    response.writeHead(200, { 'content-type': types[path.extname(file)] || 'application/octet-stream' });
    fs.createReadStream(file).pipe(response);
  });
  await new Promise((resolve) => server.listen(0, '127.0.0.1', resolve));
  origin = `http://127.0.0.1:${server.address().port}`;
  browser = await launch(WEBGPU_ARGS);
});

/** The system Chromium, headless; PELT_DUMPIO=1 passes its stderr through (GPU process logs). */
function launch(extraArgs) {
  return puppeteer.launch({
    executablePath: chromium,
    headless: true,
    dumpio: Boolean(process.env.PELT_DUMPIO),
    userDataDir: fs.mkdtempSync(path.join(os.tmpdir(), 'pelt-chromium-')),
    args: ['--headless=new', '--no-sandbox', '--disable-gpu-sandbox', ...extraArgs],
  });
}

after(async () => {
  if (browser) await browser.close();
  if (server) server.close();
});

/** A new page on the app (or fails, which fails the test). */
async function openPage({ beforeLoad, within = browser } = {}) {
  const page = await within.newPage();
  await page.setViewport(VIEWPORT);
  const problems = [];
  page.on('pageerror', (error) => problems.push(String(error)));
  page.on('console', (message) => {
    if (message.type() === 'error') problems.push(message.text());
  });
  if (beforeLoad) await beforeLoad(page);
  await page.goto(origin, { waitUntil: 'load' });
  page.problems = problems;
  return page;
}

/** Hides the figures in the canvas's corner: they change every frame and are no fur. */
async function hideOverlay(page) {
  await page.addStyleTag({ content: '#overlay { visibility: hidden; }' });
}

async function waitRunning(page) {
  await page.waitForFunction(() => window.pelt && window.pelt.state !== 'starting', { timeout: 180_000 });
  const state = await page.evaluate(() => ({ state: window.pelt.state, error: window.pelt.error }));
  assert.equal(state.state, 'running', `the page did not start: ${state.error} ${page.problems.join('; ')}`);
}

/** Waits until `count` more frames are drawn. */
async function frames(page, count) {
  const start = await page.evaluate(() => window.pelt.stats.frames_drawn);
  await page.waitForFunction((n) => window.pelt.stats && window.pelt.stats.frames_drawn >= n, { timeout: 120_000 },
    start + count);
}

/** Sets a control's value as a person would and fires its event. */
async function setControl(page, selector, value, event = 'change') {
  await page.$eval(selector, (element, v, e) => {
    element.value = v;
    element.dispatchEvent(new Event(e, { bubbles: true }));
  }, value, event);
}

/** Waits for the "making textures" note to go (texture generation blocks the page). */
async function settled(page) {
  await page.waitForFunction(() => document.getElementById('message').className !== 'info', { timeout: 120_000 });
  await frames(page, 6);
}

/**
 * The canvas as RGBA pixels from a screenshot (so what the compositor shows), saved as `name`.
 * The page is captured within its viewport (no relayout for a capture beyond it) and the PNG
 * decoded here: a page busy drawing on SwiftShader answers each round trip a frame late.
 */
async function shot(page, name) {
  page.canvasClip ??= await (await page.$('#fur')).boundingBox();
  const png = await page.screenshot({
    path: path.join(output, `${name}.png`), clip: page.canvasClip, captureBeyondViewport: false, optimizeForSpeed: true,
  });
  return decodePng(Buffer.from(png));
}

/** An 8-bit, non-interlaced RGB or RGBA PNG (what Chromium's screenshots are) as RGBA pixels. */
function decodePng(png) {
  assert.equal(png.toString('latin1', 1, 4), 'PNG', 'not a PNG');
  let offset = 8;
  let header;
  const idat = [];
  while (offset < png.length) {
    const length = png.readUInt32BE(offset);
    const type = png.toString('latin1', offset + 4, offset + 8);
    const data = png.subarray(offset + 8, offset + 8 + length);
    if (type === 'IHDR') header = { width: data.readUInt32BE(0), height: data.readUInt32BE(4), depth: data[8], colour: data[9], interlace: data[12] };
    else if (type === 'IDAT') idat.push(data);
    offset += 12 + length;
  }
  const { width, height, depth, colour, interlace } = header;
  assert.ok(depth === 8 && (colour === 2 || colour === 6) && interlace === 0, `unexpected PNG ${JSON.stringify(header)}`);
  const channels = colour === 6 ? 4 : 3;
  const raw = zlib.inflateSync(Buffer.concat(idat));
  const stride = width * channels;
  const rows = Buffer.alloc(stride * height);
  for (let y = 0; y < height; y++) {
    const filter = raw[y * (stride + 1)];
    const line = raw.subarray(y * (stride + 1) + 1, (y + 1) * (stride + 1));
    for (let i = 0; i < stride; i++) {
      const a = i >= channels ? rows[y * stride + i - channels] : 0;
      const b = y > 0 ? rows[(y - 1) * stride + i] : 0;
      const c = i >= channels && y > 0 ? rows[(y - 1) * stride + i - channels] : 0;
      let predictor = 0;
      if (filter === 1) predictor = a;
      else if (filter === 2) predictor = b;
      else if (filter === 3) predictor = (a + b) >> 1;
      else if (filter === 4) {
        const p = a + b - c;
        const [pa, pb, pc] = [Math.abs(p - a), Math.abs(p - b), Math.abs(p - c)];
        predictor = pa <= pb && pa <= pc ? a : pb <= pc ? b : c;
      }
      rows[y * stride + i] = (line[i] + predictor) & 0xff;
    }
  }
  const data = Buffer.alloc(width * height * 4, 255);
  for (let i = 0; i < width * height; i++) rows.copy(data, i * 4, i * channels, i * channels + 3);
  return { width, height, data };
}

function pixel(image, x, y) {
  const i = (y * image.width + x) * 4;
  return [image.data[i], image.data[i + 1], image.data[i + 2]];
}

/** Hue (degrees), saturation and value of an sRGB pixel. */
function hsv([r, g, b]) {
  const max = Math.max(r, g, b);
  const min = Math.min(r, g, b);
  const delta = max - min;
  let hue = 0;
  if (delta > 0) {
    if (max === r) hue = 60 * (((g - b) / delta + 6) % 6);
    else if (max === g) hue = 60 * ((b - r) / delta + 2);
    else hue = 60 * ((r - g) / delta + 4);
  }
  return [hue, max === 0 ? 0 : delta / max, max / 255];
}

/** The background: the median colour of the four corners (the scene is framed inside them). */
function background(image) {
  const samples = [];
  for (const [cx, cy] of [[2, 2], [image.width - 3, 2], [2, image.height - 3], [image.width - 3, image.height - 3]]) {
    samples.push(pixel(image, cx, cy));
  }
  return [0, 1, 2].map((c) => samples.map((s) => s[c]).sort((a, b) => a - b)[2]);
}

/** Predicates over every pixel: `{count, xs, ys}` of those that pass. */
function select(image, keep) {
  const xs = [];
  const ys = [];
  for (let y = 0; y < image.height; y++) {
    for (let x = 0; x < image.width; x++) {
      if (keep(pixel(image, x, y), x, y)) {
        xs.push(x);
        ys.push(y);
      }
    }
  }
  return { count: xs.length, xs, ys };
}

const differs = (p, q, tolerance) => Math.max(...p.map((v, c) => Math.abs(v - q[c]))) > tolerance;
const isFur = (p) => {
  const [hue, saturation, value] = hsv(p);
  return hue > 95 && hue < 150 && saturation > 0.3 && value > 0.08;
};
// Fur blended over the background at its soft edge: greener than the background's grey-blue.
const furTinted = ([r, g, b]) => g - Math.max(r, b) > 6;
const isSkin = (p) => {
  const [hue, saturation, value] = hsv(p);
  return (hue < 45 || hue > 345) && saturation > 0.08 && saturation < 0.75 && value > 0.15;
};
const mean = (values) => values.reduce((a, b) => a + b, 0) / Math.max(values.length, 1);

let shared;
async function bunnyPage() {
  if (!shared) {
    shared = await openPage();
    await waitRunning(shared);
    await hideOverlay(shared);
    await frames(shared, 6);
    shared.defaultLook = await shot(shared, 'default-look');
    await setControl(shared, '#colour', FUR_HEX);
    await settled(shared);
  }
  return shared;
}

test('the default bunny has pelt render\'s background and fur colour (look.json)', async () => {
  const page = await bunnyPage();
  const image = page.defaultLook;
  assert.deepEqual([image.width, image.height], LOOK.canvas_px, 'the canvas is not the one look.json measures');
  const bg = pixel(image, 0, 0);
  const drawn = select(image, (p) => differs(p, bg, LOOK.drawn));
  const meanColour = [0, 1, 2].map((c) => mean(drawn.xs.map((x, i) => pixel(image, x, drawn.ys[i])[c])));
  const report = `background ${bg}, fur mean ${meanColour.map((v) => v.toFixed(1))} over ${drawn.count} pixels; ` +
    `pelt render: ${LOOK.background}, ${LOOK.bunny_mean}`;
  console.log(`look: ${report}`);
  assert.ok(!differs(bg, LOOK.background, 2), `the background differs: ${report}`);
  assert.ok(drawn.count > 0.1 * image.width * image.height, `the bunny is hardly drawn: ${report}`);
  assert.ok(!differs(meanColour, LOOK.bunny_mean, LOOK.mean_bound), `the fur's colour differs: ${report}`);
});

test('fur is drawn: fur-coloured pixels stand around the bunny beyond its skin', async () => {
  const page = await bunnyPage();
  const furry = await shot(page, 'bunny');
  await setControl(page, '#length', '0.01');
  await frames(page, 4);
  const bare = await shot(page, 'bunny-short-fur');
  await setControl(page, '#length', '0.08');
  await frames(page, 6);

  const bg = background(furry);
  const furryMask = (x, y) => differs(pixel(furry, x, y), bg, 10);
  const bareMask = (x, y) => differs(pixel(bare, x, y), bg, 10);
  const body = select(bare, (p, x, y) => bareMask(x, y));
  assert.ok(body.count > 0.03 * furry.width * furry.height, `the bunny covers only ${body.count} pixels`);
  // The ring the fur adds around the silhouette: drawn with fur, background without.
  const ring = select(furry, (p, x, y) => furryMask(x, y) && !bareMask(x, y));
  const ringFur = select(furry, (p, x, y) => furryMask(x, y) && !bareMask(x, y) && furTinted(p));
  assert.ok(ring.count > 0.08 * body.count, `fur adds only ${ring.count} pixels around ${body.count}`);
  assert.ok(ringFur.count > 0.6 * ring.count, `only ${ringFur.count} of ${ring.count} ring pixels are fur-coloured`);
  const fur = select(furry, isFur);
  assert.ok(fur.count > 0.5 * body.count, `only ${fur.count} fur-coloured pixels`);
  assert.deepEqual(page.problems, []);
});

test('a pointer drag changes the fur where it presses and not elsewhere; release restores it', async () => {
  const page = await bunnyPage();
  const before = await shot(page, 'drag-before');
  await frames(page, 3);
  const still = await shot(page, 'drag-still');
  const bg = background(before);
  const noise = select(before, (p, x, y) => differs(p, pixel(still, x, y), 24));
  assert.ok(noise.count < 50, `${noise.count} pixels change with nothing touching the fur`);

  // Press on the middle of the bunny: the centroid of its pixels.
  const body = select(before, (p) => differs(p, bg, 10));
  const press = [Math.round(mean(body.xs)), Math.round(mean(body.ys))];
  assert.ok(differs(pixel(before, ...press), bg, 10), 'the bunny\'s centroid is not on the bunny');
  const radiusPx = Math.sqrt(body.count / Math.PI);
  const box = await (await page.$('#fur')).boundingBox();
  const drag = 40;
  await page.mouse.move(box.x + press[0], box.y + press[1]);
  await page.mouse.down();
  for (let step = 1; step <= 8; step++) {
    await page.mouse.move(box.x + press[0] + (drag * step) / 8, box.y + press[1]);
  }
  await page.waitForFunction(() => window.pelt.stats.touches === 1, { timeout: 30_000 });
  await frames(page, 5);
  const held = await shot(page, 'drag-held');
  await page.mouse.up();
  await frames(page, 8);
  const released = await shot(page, 'drag-released');

  const changed = select(held, (p, x, y) => differs(p, pixel(still, x, y), 24));
  assert.ok(changed.count > 150, `the drag changed only ${changed.count} pixels`);
  // The brush is a quarter of the bunny's radius and holds the fur where it landed: here 97% of
  // the changed pixels lay within 0.41 radius of the press and their centre 0.09 radius from it.
  // A pat landing 80 px (0.7 radius) to the side put that centre 0.62 radius away.
  const reach = 0.6 * radiusPx;
  const near = changed.xs.filter((x, i) => Math.hypot(x - press[0], changed.ys[i] - press[1]) < reach).length;
  assert.ok(near > 0.97 * changed.count,
    `${changed.count - near} of ${changed.count} changed pixels lie farther than ${reach.toFixed(0)} px from the press`);
  const centre = [mean(changed.xs), mean(changed.ys)];
  const offCentre = Math.hypot(centre[0] - press[0], centre[1] - press[1]);
  assert.ok(offCentre < 0.25 * radiusPx,
    `the changed fur centres ${offCentre.toFixed(0)} px from the press (more than ${(0.25 * radiusPx).toFixed(0)})`);
  const left = select(released, (p, x, y) => differs(p, pixel(still, x, y), 24));
  assert.ok(left.count < Math.max(50, 0.05 * changed.count), `${left.count} pixels stay changed after release`);
  assert.deepEqual(page.problems, []);
});

/** Clicks the tool's radio and waits until the app uses it. */
async function useTool(page, name) {
  await page.click(`input[name=tool][value=${name}]`);
  await page.waitForFunction((n) => window.pelt.stats.tool === n, { timeout: 30_000 }, name);
}

/** The bunny's pixels in `image`: the press point (their centroid) and their radius in pixels. */
function bunnyCentre(image) {
  const bg = background(image);
  const body = select(image, (p) => differs(p, bg, 10));
  const press = [Math.round(mean(body.xs)), Math.round(mean(body.ys))];
  assert.ok(differs(pixel(image, ...press), bg, 10), 'the bunny\'s centroid is not on the bunny');
  return { press, radiusPx: Math.sqrt(body.count / Math.PI) };
}

/** Changed pixels between two shots: how many, and how many lie within `reach` of `press`. */
function changes(a, b, press, reach, by = 24) {
  const changed = select(a, (p, x, y) => differs(p, pixel(b, x, y), by));
  const near = changed.xs.filter((x, i) => Math.hypot(x - press[0], changed.ys[i] - press[1]) < reach).length;
  return { count: changed.count, near };
}

test('grab: press and hold on the fur grasps it, a drag pulls it, release lets it go', async () => {
  const page = await bunnyPage();
  await useTool(page, 'grab');
  await frames(page, 2);
  const still = await shot(page, 'grab-still');
  const { press, radiusPx } = bunnyCentre(still);
  const box = await (await page.$('#fur')).boundingBox();
  await page.mouse.move(box.x + press[0], box.y + press[1]);
  await page.mouse.down();
  await page.waitForFunction(() => window.pelt.stats.grabbing === true, { timeout: 30_000 });
  for (let step = 1; step <= 8; step++) {
    await page.mouse.move(box.x + press[0], box.y + press[1] - (40 * step) / 8);
  }
  await frames(page, 6);
  const held = await shot(page, 'grab-held');
  await page.mouse.up();
  await page.waitForFunction(() => window.pelt.stats.grabbing === false, { timeout: 30_000 });
  await useTool(page, 'touch');

  // Here the grasp changed 767 pixels, all within 0.6 bunny radius of the press; without the
  // grasp nothing changes (fewer than 50 pixels move with nothing on the fur).
  const changed = changes(held, still, press, 0.6 * radiusPx);
  console.log(`grab: ${changed.count} pixels changed, ${changed.near} near the press`);
  assert.ok(changed.count > 300, `the grab changed only ${changed.count} pixels`);
  assert.ok(changed.near > 0.9 * changed.count, `${changed.count - changed.near} of ${changed.count} changed pixels lie far from the press`);
  assert.deepEqual(page.problems, []);
});

test('finger: the pointer over the fur parts it, and leaving lets it stand again', async () => {
  const page = await bunnyPage();
  await useTool(page, 'finger');
  await frames(page, 2);
  const still = await shot(page, 'finger-still');
  const { press, radiusPx } = bunnyCentre(still);
  const box = await (await page.$('#fur')).boundingBox();
  // Hovering, no button: the finger follows the mouse.
  await page.mouse.move(box.x + press[0] - 20, box.y + press[1]);
  await page.mouse.move(box.x + press[0], box.y + press[1]);
  await page.waitForFunction(() => window.pelt.stats.fingers === 1, { timeout: 30_000 });
  await frames(page, 6);
  const pressed = await shot(page, 'finger-in');
  // Off the canvas, onto the panel: the finger lifts.
  await page.mouse.move(box.x + box.width + 100, box.y + 100);
  await page.waitForFunction(() => window.pelt.stats.fingers === 0, { timeout: 30_000 });
  await useTool(page, 'touch');
  await frames(page, 8);
  const lifted = await shot(page, 'finger-out');

  // Here the finger changed 899 pixels by more than 12 levels (a hole in the fur down to the
  // skin, which in Pelt's look is close to the coat's colour), all near it.
  const changed = changes(pressed, still, press, 0.5 * radiusPx, 12);
  console.log(`finger: ${changed.count} pixels changed, ${changed.near} near the pointer`);
  assert.ok(changed.count > 150, `the finger changed only ${changed.count} pixels`);
  assert.ok(changed.near > 0.9 * changed.count, `${changed.count - changed.near} of ${changed.count} changed pixels lie far from the finger`);
  const left = changes(lifted, still, press, 0.5 * radiusPx, 12);
  assert.ok(left.count < Math.max(50, 0.1 * changed.count), `${left.count} pixels stay changed after the finger left`);
  assert.deepEqual(page.problems, []);
});

test('sponge: the fur under it turns darker and the rest keeps its colour', async () => {
  const page = await bunnyPage();
  await useTool(page, 'sponge');
  await frames(page, 2);
  const dry = await shot(page, 'sponge-dry');
  const { press, radiusPx } = bunnyCentre(dry);
  const box = await (await page.$('#fur')).boundingBox();
  await page.mouse.move(box.x + press[0], box.y + press[1]);
  await page.mouse.down();
  await page.mouse.move(box.x + press[0] + 4, box.y + press[1]);
  await page.waitForFunction(() => window.pelt.stats.wettest > 0.9, { timeout: 30_000 });
  await page.mouse.up();
  await useTool(page, 'touch');
  // Shot while the coat is still wet: it dries at the preset's rate as frames pass (here from
  // 0.8 to 0.6 in six frames).
  await frames(page, 2);
  const wet = await shot(page, 'sponge-wet');
  const wettest = await page.evaluate(() => window.pelt.stats.wettest);
  await page.click('#dry');
  await page.waitForFunction(() => window.pelt.stats.wettest === 0, { timeout: 30_000 });

  // Brightness (sum of channels) of the bunny's pixels near the press and far from it.
  const bg = background(dry);
  const brightness = (image, keep) => {
    const chosen = select(image, (p, x, y) => differs(p, bg, 10) && keep(Math.hypot(x - press[0], y - press[1])));
    return mean(chosen.xs.map((x, i) => pixel(image, x, chosen.ys[i]).reduce((a, b) => a + b, 0)));
  };
  // Here the wet fur under the sponge went from 206 to 191-202 (0.93-0.98) at wetness 0.82-0.87,
  // lowest while the heavier wet strands sag, and the fur far from it not at all; with nothing
  // wetting it, the fur under the press kept its brightness (206.1 both). Wet clumps cover about as
  // densely as dry fur (as the strand reference's do), so the darkening is the fur model's alone,
  // not bare skin showing.
  const under = (d) => d < 0.1 * radiusPx;
  const far = (d) => d > 0.6 * radiusPx;
  const report = `wetness ${wettest}: under the sponge ${brightness(dry, under).toFixed(1)} -> ` +
    `${brightness(wet, under).toFixed(1)}, ` +
    `far from it ${brightness(dry, far).toFixed(1)} -> ${brightness(wet, far).toFixed(1)}`;
  console.log(`sponge: ${report}`);
  assert.ok(wettest > 0.6, `the fur dried before the shot: ${report}`);
  assert.ok(brightness(wet, under) < 0.99 * brightness(dry, under), `the wet fur is not darker: ${report}`);
  assert.ok(Math.abs(brightness(wet, far) - brightness(dry, far)) < 0.03 * brightness(dry, far),
    `the fur far from the sponge changed: ${report}`);
  assert.deepEqual(page.problems, []);
});

test('the try-on body walks: its legs move and the furred skirt moves with them', async () => {
  const page = await bunnyPage();
  await page.click('input[name=scene][value=tryon]');
  await page.waitForFunction(() => window.pelt.stats.scene === 'tryon', { timeout: 120_000 });
  await frames(page, 5);
  const first = await page.evaluate(() => window.pelt.stats);
  const image = await shot(page, 'tryon');
  // Half a walk cycle later (the page's clock moves at most 0.25 s a frame): the legs have swapped.
  const cycle = first.walk_cycle_secs;
  assert.ok(cycle > 0.5, `the try-on has no walk cycle: ${JSON.stringify(first)}`);
  let advanced = 0;
  for (let k = 0; k < 16 && !(advanced > 0.35 * cycle && advanced < 0.65 * cycle); k++) {
    await frames(page, 1);
    const now = await page.evaluate(() => window.pelt.stats.walk_secs);
    advanced = (((now - first.walk_secs) % cycle) + cycle) % cycle;
  }
  const later = await shot(page, 'tryon-later');
  await page.click('input[name=scene][value=bunny]');
  await frames(page, 6);
  assert.equal(await page.evaluate(() => window.pelt.stats.walk_secs), null, 'the bunny walks');

  const area = image.width * image.height;
  for (const [name, picture] of [['first', image], ['later', later]]) {
    const skin = select(picture, isSkin);
    const fur = select(picture, isFur);
    assert.ok(skin.count > 0.02 * area, `${name}: only ${skin.count} body-coloured pixels`);
    assert.ok(fur.count > 0.005 * area, `${name}: only ${fur.count} fur-coloured pixels`);
    // The skirt sits on the hips: below the head and above the feet of the body.
    const top = Math.min(...skin.ys);
    const bottom = Math.max(...skin.ys);
    const furY = (mean(fur.ys) - top) / (bottom - top);
    assert.ok(furY > 0.3 && furY < 0.75, `${name}: the fur's centre is at ${furY.toFixed(2)} of the body's height`);
    assert.ok(Math.min(...fur.ys) > top + 0.15 * (bottom - top), `${name}: fur reaches the head`);
  }
  // The legs: body-coloured pixels below the skirt's hem (the lowest fur pixel of either shot).
  const fur = select(image, isFur);
  const furLater = select(later, isFur);
  const hem = Math.max(...fur.ys, ...furLater.ys);
  const legs = (picture) => select(picture, (p, x, y) => y > hem && isSkin(p));
  const legsFirst = legs(image);
  const legsMoved = select(image, (p, x, y) => y > hem && (isSkin(p) || isSkin(pixel(later, x, y))) &&
    differs(p, pixel(later, x, y), 24));
  // The skirt: fur-coloured pixels in either shot that changed.
  const skirtMoved = select(image, (p, x, y) => (isFur(p) || isFur(pixel(later, x, y))) &&
    differs(p, pixel(later, x, y), 24));
  const report = `${advanced.toFixed(2)} s of a ${cycle.toFixed(2)} s walk apart: ${legsMoved.count} leg pixels ` +
    `of ${legsFirst.count} changed, ${skirtMoved.count} skirt pixels of ${fur.count}`;
  console.log(`walk: ${report}`);
  assert.ok(advanced > 0.35 * cycle && advanced < 0.65 * cycle, `the walk's clock did not move on: ${report}`);
  // A frozen walk changes neither (a still scene changes fewer than 50 pixels, the drag test shows).
  assert.ok(legsFirst.count > 0.002 * area, `no legs below the skirt: ${report}`);
  assert.ok(legsMoved.count > 0.4 * legsFirst.count, `the legs do not move: ${report}`);
  assert.ok(skirtMoved.count > 0.1 * fur.count, `the skirt does not move with the legs: ${report}`);
  assert.deepEqual(page.problems, []);
});

test('a bad preset file is a message naming it, and the page keeps drawing', async () => {
  const page = await bunnyPage();
  const file = path.join(output, 'bad-preset.toml');
  fs.writeFileSync(file, 'layers = 9000\n');
  const input = await page.$('#preset-file');
  await input.uploadFile(file);
  // The error about this file: the wait must not end on an earlier state of the message box.
  await page.waitForFunction(
    () => {
      const message = document.getElementById('message');
      return message.className === 'error' && message.textContent.includes('bad-preset.toml');
    },
    { timeout: 60_000 },
  );
  const text = await page.$eval('#message', (e) => e.textContent);
  assert.match(text, /bad-preset\.toml/);
  assert.match(text, /layers/);
  await frames(page, 2);
  assert.ok(await page.$eval('#message', (e) => e.className === 'error'), 'the page went on without the message');
  await page.$eval('#message', (e) => { e.className = ''; e.style.display = 'none'; });
});

test('two touches at once pat two places', async () => {
  const page = await bunnyPage();
  const still = await shot(page, 'touch-still');
  const bg = background(still);
  const body = select(still, (p) => differs(p, bg, 10));
  const cx = mean(body.xs);
  const cy = mean(body.ys);
  // Two points on the bunny, left and right of its centre.
  const left = body.xs.map((x, i) => [x, body.ys[i]]).filter(([x, y]) => x < cx - 40 && Math.abs(y - cy) < 20)[0];
  const right = body.xs.map((x, i) => [x, body.ys[i]]).filter(([x, y]) => x > cx + 30 && Math.abs(y - cy) < 20)[0];
  assert.ok(left && right, 'no two points on the bunny');
  const box = await (await page.$('#fur')).boundingBox();
  const session = await page.createCDPSession();
  const points = (dy) => [
    { x: box.x + left[0] + 8, y: box.y + left[1] + dy, id: 1 },
    { x: box.x + right[0] - 8, y: box.y + right[1] + dy, id: 2 },
  ];
  await session.send('Input.dispatchTouchEvent', { type: 'touchStart', touchPoints: points(0) });
  await session.send('Input.dispatchTouchEvent', { type: 'touchMove', touchPoints: points(15) });
  await page.waitForFunction(() => window.pelt.stats.touches === 2, { timeout: 30_000 });
  await session.send('Input.dispatchTouchEvent', { type: 'touchEnd', touchPoints: [] });
  await page.waitForFunction(() => window.pelt.stats.touches === 0, { timeout: 30_000 });
  await session.detach();
  assert.deepEqual(page.problems, []);
});

test('the groomed Fox draws: bald and shorter where its groom says, longer on the chest and tail', async () => {
  const page = await bunnyPage();
  await page.click('input[name=scene][value=fox]');
  await page.waitForFunction(() => window.pelt.stats.preset === 'fox_groomed', { timeout: 120_000 });
  await settled(page);
  await frames(page, 4);
  const groomed = await shot(page, 'fox-groomed');
  // fox.toml: the same coat, uniform at the length the groom gives the Fox's body.
  await setControl(page, '#preset', 'fox');
  await page.waitForFunction(() => window.pelt.stats.preset === 'fox', { timeout: 120_000 });
  await settled(page);
  await frames(page, 4);
  const uniform = await shot(page, 'fox-uniform');
  assert.ok(await page.$eval('input[name=scene][value=fox]', (e) => e.checked), 'the scene menu does not show the Fox');

  const bg = background(groomed);
  const drawnGroomed = (x, y) => differs(pixel(groomed, x, y), bg, 10);
  const drawnUniform = (x, y) => differs(pixel(uniform, x, y), bg, 10);
  const area = groomed.width * groomed.height;
  const fox = select(groomed, (p, x, y) => drawnGroomed(x, y));
  const onlyUniform = select(groomed, (p, x, y) => drawnUniform(x, y) && !drawnGroomed(x, y));
  const onlyGroomed = select(groomed, (p, x, y) => drawnGroomed(x, y) && !drawnUniform(x, y));
  const report = `the groomed Fox covers ${fox.count} pixels; ${onlyUniform.count} only the uniform coat covers, ` +
    `${onlyGroomed.count} only the groomed one`;
  console.log(`fox: ${report}`);
  assert.ok(fox.count > 0.03 * area, `the Fox is hardly drawn: ${report}`);
  // The bald nose, eyes and inner ears and the short face and legs: the uniform coat reaches
  // where the groomed one does not (here 10% of the Fox's pixels); the ruff and the tail reach
  // where the uniform one does not (here 3%). A uniform length (no groom) gives one of the two.
  assert.ok(onlyUniform.count > 0.05 * fox.count, `the groom shortens nothing: ${report}`);
  assert.ok(onlyGroomed.count > 0.012 * fox.count, `the groom lengthens nothing: ${report}`);
  assert.deepEqual(page.problems, []);
});

/** The 4-connected regions of the pixels `inside(p)` keeps, each as its pixels' indices. */
function regions(image, inside) {
  const { width, height } = image;
  const seen = new Uint8Array(width * height);
  const found = [];
  for (let start = 0; start < width * height; start++) {
    if (seen[start] || !inside(pixel(image, start % width, Math.floor(start / width)))) continue;
    const region = [start];
    seen[start] = 1;
    for (let k = 0; k < region.length; k++) {
      const i = region[k];
      const [x, y] = [i % width, Math.floor(i / width)];
      for (const [nx, ny] of [[x - 1, y], [x + 1, y], [x, y - 1], [x, y + 1]]) {
        const n = ny * width + nx;
        if (nx >= 0 && ny >= 0 && nx < width && ny < height && !seen[n] && inside(pixel(image, nx, ny))) {
          seen[n] = 1;
          region.push(n);
        }
      }
    }
    found.push(region);
  }
  return found;
}

test('the herd: sixteen Foxes walk on the ground, each at its own phase', async () => {
  const page = await openPage();
  await waitRunning(page);
  await hideOverlay(page);
  await page.click('input[name=scene][value=herd]');
  await page.waitForFunction(() => window.pelt.stats.scene === 'herd', { timeout: 120_000 });
  // Green fur, which neither the ground nor the background has (the herd is made again with it).
  await setControl(page, '#colour', FUR_HEX);
  await settled(page);
  const clock = await page.evaluate(() => window.pelt.stats);
  const first = await shot(page, 'herd');
  // The Foxes walk on the spot, so a whole cycle later they stand as before: wait about half a
  // cycle, by the page's clock (a frame moves it at most 0.25 s), not a count of frames.
  const cycle = clock.walk_cycle_secs;
  assert.ok(cycle > 0.5, `the herd has no walk cycle: ${JSON.stringify(clock)}`);
  let advanced = 0;
  for (let k = 0; k < 16 && !(advanced > 0.35 * cycle && advanced < 0.65 * cycle); k++) {
    await frames(page, 1);
    const now = await page.evaluate(() => window.pelt.stats.walk_secs);
    advanced = (((now - clock.walk_secs) % cycle) + cycle) % cycle;
  }
  const later = await shot(page, 'herd-later');
  const foxes = regions(first, isFur).filter((region) => region.length >= 20);
  const at = (image, i) => pixel(image, i % image.width, Math.floor(i / image.width));
  const walking = foxes.filter((region) =>
    region.filter((i) => differs(at(first, i), at(later, i), 24)).length > 0.1 * region.length);
  const report = `${foxes.length} fur-coloured regions of 20 pixels or more, ${walking.length} of them moved ` +
    `(${foxes.map((r) => r.length).join(', ')})`;
  console.log(`herd: ${report}`);
  const bg = background(first);
  const ground = select(first, (p) => differs(p, bg, 10) && !isFur(p) && !furTinted(p)).count;
  console.log(`herd: ${ground} ground pixels of ${first.width * first.height}`);
  // Overlapping Foxes merge into one region (here 16 Foxes made 10); one Fox alone makes one or two.
  assert.ok(foxes.length >= 8, `fewer Foxes than the herd holds: ${report}`);
  assert.ok(walking.length >= 6, `the Foxes do not walk: ${report}`);
  assert.ok(ground > 0.1 * first.width * first.height, `the herd stands on no ground (${ground} pixels)`);
  assert.deepEqual(page.problems, []);
  await page.close();
});

test('the key light casts the bunny\'s shadow on the ground, and Shift + drag moves it', async () => {
  const page = await openPage();
  await waitRunning(page);
  await hideOverlay(page);
  // Shadows are on by default (Pelt's studio): the switch turns them off, then on again.
  assert.ok(await page.$eval('#shadows', (box) => box.checked), 'shadows are not on by default');
  await page.click('#ground');
  await frames(page, 4);
  const shadowed = await shot(page, 'light-shadow');
  await page.click('#shadows');
  await frames(page, 4);
  const bare = await shot(page, 'light-ground');
  await page.click('#shadows');
  await frames(page, 4);

  // The ground: grey pixels (the fur is brown, the body absent) unlike the top-left corner (the
  // background, which the ground does not reach).
  const bg = pixel(bare, 2, 2);
  const ground = select(bare, (p) => Math.max(...p) - Math.min(...p) < 24 && differs(p, bg, 12));
  const darker = (before, after) => ground.xs.filter((x, i) => {
    const [a, b] = [pixel(before, x, ground.ys[i]), pixel(after, x, ground.ys[i])];
    return b.every((v, c) => v < a[c] - 10);
  }).length;
  const area = bare.width * bare.height;
  const shaded = darker(bare, shadowed);
  console.log(`light: ${ground.count} ground pixels, ${shaded} darker with shadows`);
  assert.ok(ground.count > area / 10, `the ground is hardly drawn (${ground.count} pixels)`);
  assert.ok(shaded > area / 100, `the bunny's shadow does not darken the ground (${shaded} pixels)`);

  // Shift + drag beside the bunny turns the light half round: the shadow moves.
  const box = await (await page.$('#fur')).boundingBox();
  await page.keyboard.down('Shift');
  await page.mouse.move(box.x + 20, box.y + 20);
  await page.mouse.down();
  for (let step = 1; step <= 9; step++) await page.mouse.move(box.x + 20 + 50 * step, box.y + 20);
  await page.mouse.up();
  await page.keyboard.up('Shift');
  const light = await page.evaluate(() => window.pelt.light);
  assert.ok(Array.isArray(light), 'the dragged light is not fixed in the world');
  await frames(page, 4);
  const moved = await shot(page, 'light-moved');
  const [left, came] = [darker(moved, shadowed), darker(shadowed, moved)];
  console.log(`light: dragged to ${light.map((a) => a.toFixed(0))}; ${left} ground pixels darkened where the ` +
    `shadow was, ${came} where it went`);
  // The key light's shadow falls behind the bunny, mostly hidden by it (here 910 pixels showed);
  // turned half round, it falls in front (13,636).
  assert.ok(left > area / 400 && came > area / 200, `the shadow did not move with the light (${left}, ${came})`);
  assert.deepEqual(page.problems, []);
  await page.close();
});

test('without WebGPU the page says so instead of showing a blank canvas', async () => {
  const page = await openPage({
    beforeLoad: (p) => p.evaluateOnNewDocument(() => {
      delete Navigator.prototype.gpu;
    }),
  });
  await page.waitForFunction(() => window.pelt && window.pelt.state === 'no-webgpu', { timeout: 30_000 });
  const text = await page.$eval('#message', (e) => e.textContent);
  assert.match(text, /no WebGPU/);
  assert.ok(await page.$eval('#message', (e) => getComputedStyle(e).display !== 'none'));
  await page.close();
});

test('WebGPU with no adapter (Chromium without --enable-unsafe-webgpu) is a message too', async () => {
  const plain = await launch([]);
  try {
    const page = await openPage({ within: plain });
    await page.waitForFunction(() => window.pelt && window.pelt.state === 'no-webgpu', { timeout: 30_000 });
    const text = await page.$eval('#message', (e) => e.textContent);
    assert.match(text, /no adapter/);
    assert.ok(await page.$eval('#message', (e) => getComputedStyle(e).display !== 'none'));
  } finally {
    await plain.close();
  }
});

test('figures: time to the first frame, frame time, textures and simulation', async () => {
  // Alone in the browser: a page still drawing in another tab would share SwiftShader's threads.
  if (shared) {
    await shared.close();
    shared = null;
  }
  const page = await openPage();
  await waitRunning(page);
  await frames(page, 5);
  await page.screenshot({ path: path.join(output, 'page.png') });
  // The overlay names the adapter (its last line), even where wgpu's adapter info is empty.
  const adapterLine = await page.$eval('#overlay', (e) => e.textContent.split('\n')[2] || '');
  assert.ok(adapterLine.trim().length > 0, `the overlay names no adapter: ${JSON.stringify(adapterLine)}`);
  // Every control stays inside the side panel (a wide preset list once pushed them past it).
  const overflow = await page.evaluate(() => {
    const panel = document.getElementById('panel').getBoundingClientRect();
    return [...document.querySelectorAll('#panel fieldset, #panel select, #panel input')]
      .filter((e) => e.getBoundingClientRect().right > panel.right + 0.5)
      .map((e) => e.id || e.tagName);
  });
  assert.deepEqual(overflow, [], 'controls reach past the panel');
  const count = 8;
  const start = await page.evaluate(() => ({ t: performance.now(), n: window.pelt.stats.frames_drawn }));
  await frames(page, count);
  const end = await page.evaluate(() => ({ t: performance.now(), n: window.pelt.stats.frames_drawn }));
  const figures = await page.evaluate(() => ({ firstFrameMs: window.pelt.firstFrameMs, ...window.pelt.stats }));
  figures.measuredFrameMs = (end.t - start.t) / (end.n - start.n);
  figures.canvas = await page.$eval('#fur', (c) => [c.width, c.height]);
  const wasm = fs.statSync(path.join(dist, 'pelt_web_bg.wasm')).size;
  const all = { wasmBytes: wasm, ...figures };
  console.log(`figures: ${JSON.stringify(all)}`);
  fs.writeFileSync(path.join(output, 'figures.json'), JSON.stringify(all, null, 1));
  assert.ok(figures.firstFrameMs > 0 && end.n >= start.n + count);
  assert.deepEqual(page.problems, []);
  await page.close();
});
