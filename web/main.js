// The page's controls and events; Pelt itself (fur, simulation, drawing) is the wasm module.
// Every call into it may throw a message string: it is shown and the page goes on.
import init, { PeltApp, preset_names, web_tile_px } from './pelt_web.js';

const canvas = document.getElementById('fur');
const overlay = document.getElementById('overlay');
const messageBox = document.getElementById('message');
const $ = (id) => document.getElementById(id);

// For tests and curious people: the page's state and figures.
// firstFrameMs counts from the navigation's start (performance.now()'s origin): the HTML, the wasm's
// download and compilation, the fur and its textures, the device and the first frame.
const page = { state: 'starting', error: null, firstFrameMs: null };
window.pelt = page;

function show(text, kind = 'error') {
  messageBox.textContent = text;
  // A cleared message keeps no kind: an 'error' class left on the hidden box read as an error.
  messageBox.className = text ? kind : '';
  messageBox.style.display = text ? 'block' : 'none';
  if (kind === 'error' && text) page.error = text;
}

let app = null;
let scene = 'bunny';
let presetName = 'default';

/** Runs `action` on the app, showing what it throws; true when it went through. */
function attempt(action) {
  if (!app) return false;
  try {
    action(app);
    return true;
  } catch (error) {
    show(String(error));
    return false;
  }
}

/** Shows `note` while `action` runs (texture generation blocks the page's one thread). */
async function slow(note, action) {
  show(note, 'info');
  await new Promise((resolve) => requestAnimationFrame(() => setTimeout(resolve, 0)));
  if (attempt(action)) show('');
  syncControls();
}

// Canvas size: CSS size times devicePixelRatio, exact where the browser reports device pixels.
let devicePx = null;
function canvasSize() {
  if (devicePx) return devicePx;
  const ratio = window.devicePixelRatio || 1;
  return [Math.round(canvas.clientWidth * ratio), Math.round(canvas.clientHeight * ratio)];
}
try {
  new ResizeObserver((entries) => {
    const entry = entries[entries.length - 1];
    const box = entry.devicePixelContentBoxSize && entry.devicePixelContentBoxSize[0];
    devicePx = box ? [box.inlineSize, box.blockSize] : null;
  }).observe(canvas, { box: 'device-pixel-content-box' });
} catch (_) {
  devicePx = null; // Older browsers: the fallback above follows clientWidth and devicePixelRatio.
}

function frame(nowMs) {
  if (!app) return;
  const [width, height] = canvasSize();
  if (canvas.width !== width || canvas.height !== height) {
    canvas.width = width;
    canvas.height = height;
  }
  try {
    const drawn = app.frame(nowMs, width, height, canvas.clientWidth, canvas.clientHeight);
    if (drawn && page.firstFrameMs === null) {
      page.firstFrameMs = performance.now();
      page.state = 'running';
    }
  } catch (error) {
    const text = String(error);
    if (text.includes('device was lost')) {
      restart(text);
      return;
    }
    show(text);
  }
  const stats = JSON.parse(app.stats());
  page.stats = stats;
  overlay.textContent =
    `frame ${stats.frame_ms.toFixed(1)} ms   simulation ${stats.sim_ms.toFixed(2)} ms\n` +
    `textures ${stats.texture_ms.toFixed(0)} ms (${stats.tile_px} px tiles)   ${stats.layers} layers, ${stats.vertices} vertices\n` +
    `${stats.adapter || page.adapterLabel}`;
  requestAnimationFrame(frame);
}

async function start() {
  page.state = 'starting';
  // The first framing needs the canvas's real shape.
  const [width, height] = canvasSize();
  canvas.width = Math.max(width, 1);
  canvas.height = Math.max(height, 1);
  try {
    app = await PeltApp.start(canvas, scene, presetName);
  } catch (error) {
    page.state = 'failed';
    show(`Pelt could not start: ${error}`);
    return;
  }
  applyWind();
  attempt((a) => a.set_tool(tool));
  syncControls();
  requestAnimationFrame(frame);
}

function restart(why) {
  show(`${why}. Starting again…`, 'info');
  if (app) app.free();
  app = null;
  start();
}

// The scene the controls were last synced with.
let sceneShown = null;
function syncControls() {
  if (!app) return;
  // A scene or preset change can bring the other along (a Fox preset shows the Fox).
  scene = app.scene();
  presetName = app.preset_name();
  for (const radio of document.querySelectorAll('input[name=scene]')) radio.checked = radio.value === scene;
  if ([...$('preset').options].some((o) => o.value === presetName)) $('preset').value = presetName;
  $('length').value = app.length();
  $('length-value').textContent = app.length().toFixed(3);
  $('colour').value = app.colour();
  // The herd stands on a ground (the switch turns it off again).
  if (scene === 'herd' && sceneShown !== 'herd') $('ground').checked = true;
  sceneShown = scene;
  attempt((a) => {
    a.set_shadows($('shadows').checked);
    a.set_ground($('ground').checked);
  });
  syncLight();
}

/** The light's angles beside its controls ("follows the camera" until it is moved). */
function syncLight() {
  if (!app) return;
  const angles = app.light_angles();
  $('light-value').textContent = angles.length === 2
    ? `azimuth ${angles[0].toFixed(0)}°, elevation ${angles[1].toFixed(0)}°` : 'follows the camera';
  page.light = angles.length === 2 ? [angles[0], angles[1]] : null;
}

function applyWind() {
  const strength = Number($('wind').value);
  const direction = Number($('wind-dir').value);
  $('wind-value').textContent = strength.toFixed(1);
  $('wind-dir-value').textContent = `${direction}°`;
  attempt((a) => a.set_wind(strength, direction));
}

// Pointers: one that lands on the fur takes the tool; others turn the view, two of them pinch-zoom.
// With Shift held a drag moves the key light. The finger also follows a hovering mouse.
let tool = 'touch';
const pressing = new Set();
const turning = new Map();
const lighting = new Map();
function local(event) {
  const rect = canvas.getBoundingClientRect();
  return [event.clientX - rect.left, event.clientY - rect.top];
}
canvas.addEventListener('pointerdown', (event) => {
  if (!app) return;
  canvas.setPointerCapture(event.pointerId);
  const [x, y] = local(event);
  if (event.shiftKey) {
    lighting.set(event.pointerId, [x, y]);
  } else if (event.button === 0 && !event.altKey && app.pointer_down(event.pointerId, x, y)) {
    pressing.add(event.pointerId);
  } else {
    turning.set(event.pointerId, [x, y]);
  }
  event.preventDefault();
});
canvas.addEventListener('pointermove', (event) => {
  if (!app) return;
  const [x, y] = local(event);
  if (lighting.has(event.pointerId)) {
    const [px, py] = lighting.get(event.pointerId);
    app.drag_light(x - px, y - py);
    lighting.set(event.pointerId, [x, y]);
    syncLight();
  } else if (pressing.has(event.pointerId)) {
    app.pointer_move(event.pointerId, x, y);
  } else if (turning.has(event.pointerId)) {
    const [px, py] = turning.get(event.pointerId);
    if (turning.size === 2) {
      const [other] = [...turning].filter(([id]) => id !== event.pointerId).map(([, p]) => p);
      const before = Math.hypot(px - other[0], py - other[1]);
      const after = Math.hypot(x - other[0], y - other[1]);
      if (before > 0 && after > 0) app.zoom(before / after);
    } else if (turning.size === 1) {
      app.orbit(x - px, y - py);
    }
    turning.set(event.pointerId, [x, y]);
  } else if (tool === 'finger' && event.pointerType === 'mouse') {
    app.pointer_move(event.pointerId, x, y);
  }
});
function release(event) {
  if (app && (pressing.delete(event.pointerId) || tool === 'finger')) app.pointer_up(event.pointerId);
  turning.delete(event.pointerId);
  lighting.delete(event.pointerId);
}
canvas.addEventListener('pointerup', release);
canvas.addEventListener('pointercancel', release);
canvas.addEventListener('lostpointercapture', release);
canvas.addEventListener('pointerleave', release);
canvas.addEventListener('wheel', (event) => {
  event.preventDefault();
  attempt((a) => a.zoom(Math.pow(1.0015, event.deltaY)));
}, { passive: false });

// Controls.
for (const radio of document.querySelectorAll('input[name=tool]')) {
  radio.addEventListener('change', () => {
    if (attempt((a) => a.set_tool(radio.value))) {
      tool = radio.value;
      pressing.clear();
    }
  });
}
$('dry').addEventListener('click', () => attempt((a) => a.dry()));
for (const radio of document.querySelectorAll('input[name=scene]')) {
  radio.addEventListener('change', () => {
    // The Fox brings its groomed preset (textures to make); other scenes keep the preset.
    slow(`loading the ${radio.value} scene…`, (a) => a.set_scene(radio.value));
  });
}
$('frame').addEventListener('click', () => attempt((a) => a.reset_view()));
$('preset').addEventListener('change', (event) => {
  presetName = event.target.value;
  slow(`making the ${presetName} textures…`, (a) => a.set_preset(presetName));
});
$('preset-file').addEventListener('change', async (event) => {
  const file = event.target.files && event.target.files[0];
  if (!file) return;
  let text;
  try {
    text = await file.text();
  } catch (error) {
    show(`could not read ${file.name}: ${error}`);
    return;
  }
  slow(`making the textures of ${file.name}…`, (a) => a.load_preset_text(text, file.name));
});
$('length').addEventListener('input', (event) => {
  $('length-value').textContent = Number(event.target.value).toFixed(3);
});
$('length').addEventListener('change', (event) => attempt((a) => a.set_length(Number(event.target.value))));
$('colour').addEventListener('change', (event) => {
  slow('making textures…', (a) => a.set_colour(event.target.value));
});
$('shadows').addEventListener('change', (event) => attempt((a) => a.set_shadows(event.target.checked)));
$('ground').addEventListener('change', (event) => attempt((a) => a.set_ground(event.target.checked)));
$('follow-light').addEventListener('click', () => {
  attempt((a) => a.follow_camera_light());
  syncLight();
});
$('wind').addEventListener('input', applyWind);
$('wind-dir').addEventListener('input', applyWind);

/** "vendor architecture (description)" from WebGPU's adapter info, or "" when it says nothing. */
function adapterLabel(adapter) {
  const info = adapter && adapter.info;
  if (!info) {
    return '';
  }
  const name = [info.vendor, info.architecture].filter((s) => s).join(' ');
  const description = info.description && info.description !== name ? info.description : '';
  return [name, description && `(${description})`].filter((s) => s).join(' ');
}

async function main() {
  if (!navigator.gpu) {
    page.state = 'no-webgpu';
    show('This browser has no WebGPU, which Pelt draws with. Try a current Chrome, Edge or Safari, ' +
      'or Firefox with WebGPU enabled.');
    overlay.textContent = 'no WebGPU';
    return;
  }
  // WebGPU can be there and still offer no adapter (switched off, or the GPU is blocklisted):
  // say so before downloading the WebAssembly.
  let adapter = null;
  try {
    adapter = await navigator.gpu.requestAdapter();
  } catch (_) {
    adapter = null;
  }
  // wgpu leaves the adapter's name empty on some browsers (SwiftShader in Chromium): the page
  // asks WebGPU itself for what to show instead.
  page.adapterLabel = adapterLabel(adapter);
  if (!adapter) {
    page.state = 'no-webgpu';
    show('This browser has WebGPU but offers no adapter to draw with (WebGPU switched off, or this GPU ' +
      'blocklisted). Check chrome://gpu or your browser\'s WebGPU setting.');
    overlay.textContent = 'no WebGPU adapter';
    return;
  }
  try {
    await init();
  } catch (error) {
    page.state = 'failed';
    show(`Pelt's WebAssembly did not load: ${error}`);
    return;
  }
  for (const name of preset_names()) {
    const option = document.createElement('option');
    option.value = option.textContent = name;
    $('preset').append(option);
  }
  $('tile-note').textContent = `On the web the shell textures are made at most ${web_tile_px()} texels across ` +
    '(the presets ask for 512) and repeated twice as often, so start-up stays short on one thread.';
  await start();
}
main();
