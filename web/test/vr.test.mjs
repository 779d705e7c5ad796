// The VR page end to end: `vrdeform serve liver`, headless Chromium (Debian's, driven by
// playwright-core) with an emulated Quest (iwer, installed over Chromium's own navigator.xr). The
// page enters an immersive-vr session and draws the liver in both eyes; mesh frames keep
// arriving; the emulated right controller is lowered onto the liver (the server reports a force
// and, with no glove connected, the controller vibrates) and then closes its trigger on a ridge
// (the server reports a grasp). Usage: node vr.test.mjs [VRDEFORM] (or $VRDEFORM).
import assert from 'node:assert/strict';
import { spawn } from 'node:child_process';
import { existsSync, mkdtempSync, readFileSync, rmSync, writeFileSync } from 'node:fs';
import { tmpdir } from 'node:os';
import path from 'node:path';
import { test } from 'node:test';
import { fileURLToPath } from 'node:url';
import { chromium } from 'playwright-core';

const here = path.dirname(fileURLToPath(import.meta.url));
const vrdeform = process.argv[2] || process.env.VRDEFORM || path.resolve(here, '../../build/release/apps/vrdeform');
const chromiumPath = process.env.CHROMIUM || '/usr/bin/chromium';
const iwerScript = path.resolve(here, '../node_modules/iwer/build/iwer.js');

// The controller mapping's defaults (docs/vr.md#hand-input): the pinch's middle is `reach` ahead
// of the controller; the index sits half the open gap plus a fingertip radius above it (along the
// controller's up).
const REACH = 0.03;
const OPEN_HALF = 0.03;
// A controller pointing straight down with its up along +x ([x, y, z, w]): the pinch closes
// along x, as the scene's scripted grasp does.
const POINTING_DOWN = [-0.5, -0.5, -0.5, 0.5];
const sleep = (ms) => new Promise((resolve) => setTimeout(resolve, ms));

async function until(what, check, timeoutMs = 10000) {
  const end = Date.now() + timeoutMs;
  let last;
  while (Date.now() < end) {
    last = await check();
    if (last) return last;
    await sleep(50);
  }
  throw new Error(`timed out after ${timeoutMs} ms waiting for ${what}`);
}

// `vrdeform COMMAND --port 0 EXTRA...` (default: serve liver), and the address it serves on.
function startServer(extra = [], command = ['serve', 'liver']) {
  const server = spawn(vrdeform, [...command, '--port', '0', ...extra], { stdio: ['ignore', 'pipe', 'pipe'] });
  let output = '';
  const exited = new Promise((resolve) => server.on('exit', (code, signal) => resolve({ code, signal })));
  const url = new Promise((resolve, reject) => {
    const timer = setTimeout(() => reject(new Error(`vrdeform serve did not start in 90 s:\n${output}`)), 90000);
    server.stdout.on('data', (chunk) => {
      output += chunk;
      const m = output.match(/serving on (https?:\/\/127\.0\.0\.1:\d+\/)/);
      if (m) {
        clearTimeout(timer);
        resolve(m[1]);
      }
    });
    server.stderr.on('data', (chunk) => (output += chunk));
    exited.then(({ code }) => {
      clearTimeout(timer);
      reject(new Error(`vrdeform serve exited with ${code}:\n${output}`));
    });
  });
  return { server, url, exited, output: () => output };
}

// Headless Chromium with WebGL in software; `args` adds flags.
function openHeadset(profile, args = []) {
  return chromium.launchPersistentContext(profile, {
    executablePath: chromiumPath,
    headless: true,
    viewport: { width: 800, height: 450 },
    args: [
      '--no-sandbox',
      '--disable-gpu',
      '--disable-background-networking',
      '--disable-dev-shm-usage',
      '--use-angle=swiftshader',
      '--enable-unsafe-swiftshader',
      ...args,
    ],
  });
}

// A page with the emulated Quest 3 (stereo, looking down at the table) installed before any of
// its scripts, and its errors collected.
async function headsetPage(context) {
  const page = context.pages()[0] || (await context.newPage());
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  page.on('console', (m) => m.type() === 'error' && errors.push(m.text()));
  await page.addInitScript({ path: iwerScript });
  await page.addInitScript(() => {
    const device = new IWER.XRDevice(IWER.metaQuest3, { stereoEnabled: true });
    device.installRuntime({ forceInstall: true });
    device.quaternion.set(-Math.sin(Math.PI / 12), 0, 0, Math.cos(Math.PI / 12)); // 30 degrees down
    window.__xrDevice = device;
  });
  return { page, errors };
}

// Starts `vrdeform serve liver` (or `command`) with `serverArgs`, then Chromium with the flags
// `browserArgs(serverOutput)` gives; both are closed when the test ends. stop() closes the browser
// and checks that the server stops cleanly on SIGTERM.
async function serveAndBrowse(t, serverArgs = [], browserArgs = () => [], command = undefined) {
  const { server, url, exited, output } = startServer(serverArgs, command);
  const profile = mkdtempSync(path.join(tmpdir(), 'vrdeform-chromium-'));
  let browser;
  t.after(async () => {
    if (browser) await browser.close().catch(() => {});
    if (server.exitCode === null) server.kill('SIGKILL');
    rmSync(profile, { recursive: true, force: true });
  });
  const base = await url;
  browser = await openHeadset(profile, browserArgs(output()));
  const stop = async () => {
    await browser.close();
    browser = null;
    server.kill('SIGTERM');
    const { code } = await exited;
    assert.equal(code, 0, output());
  };
  const status = async () => (await fetch(`${base}status.json`)).json();
  return { base, browser, output, status, stop, exited };
}

test('the VR page in an emulated headset: both eyes, mesh frames, poke and grasp', { timeout: 150000 }, async (t) => {
  const { base, browser, status, stop } = await serveAndBrowse(t);
  const { page, errors } = await headsetPage(browser);
  await page.goto(base);
  await until('the scene and mesh frames', () => page.evaluate(() => vrdeform.state.framesReceived > 3), 30000);
  const scene = await page.evaluate(() => vrdeform.state.scene);
  assert.equal(scene.name, 'liver');
  assert.deepEqual(scene.fingers, ['thumb', 'index', 'middle']);

  // Enter VR with the page's own button.
  await page.click('#VRButton');
  await until('an immersive-vr session', () => page.evaluate(() => vrdeform.state.xrPresenting && vrdeform.state.xrFrames > 10));

  // Both eyes: the left and the right half of the canvas each show liver-coloured pixels.
  const eyes = await page.evaluate(
    () =>
      new Promise((resolve) => {
        vrdeform.afterRender = (gl, presenting) => {
          if (!presenting) return;
          vrdeform.afterRender = null;
          const w = gl.drawingBufferWidth, h = gl.drawingBufferHeight;
          const px = new Uint8Array(4 * w * h);
          gl.readPixels(0, 0, w, h, gl.RGBA, gl.UNSIGNED_BYTE, px);
          const body = [0, 0];
          for (let i = 0; i < w * h; ++i) {
            const [r, g, b] = [px[4 * i], px[4 * i + 1], px[4 * i + 2]];
            if (r > 80 && r > 1.6 * g && r > 1.6 * b) body[i % w < w / 2 ? 0 : 1]++;
          }
          resolve({ w, h, left: body[0], right: body[1] });
        };
      }),
  );
  const half = (eyes.w * eyes.h) / 2;
  assert.ok(eyes.left > 0.005 * half, `left eye: ${eyes.left} liver pixels of ${half}`);
  assert.ok(eyes.right > 0.005 * half, `right eye: ${eyes.right} liver pixels of ${half}`);

  // Mesh frames keep coming while in VR, and the server keeps stepping. (The server's step moves
  // on at its frame rate, and the page may have frames queued from before step0: so waited for.)
  const frames0 = await page.evaluate(() => vrdeform.state.framesReceived);
  const step0 = (await status()).step;
  await until('mesh frames in VR', () => page.evaluate((n) => vrdeform.state.framesReceived > n + 5, frames0)).catch(
    async (e) => assert.fail(`${e.message}: ${JSON.stringify(await page.evaluate(() => vrdeform.state))}`),
  );
  await until('the server to step on', async () => (await status()).step > step0);

  // Moves the emulated right controller so that its pinch middle sweeps from 4 cm above `middle`
  // (scene coordinates) down onto it.
  const lower = async (middle, ms) => {
    for (let k = 0; k <= 20; ++k) {
      const above = 0.04 * (1 - k / 20);
      const ray = [middle[0], middle[1] + REACH + above, middle[2]];
      await page.evaluate(
        ({ ray, q }) => {
          const [x, y, z] = vrdeform.toXr(ray);
          const c = __xrDevice.controllers.right;
          c.position.set(x, y, z);
          c.quaternion.set(...q);
        },
        { ray, q: POINTING_DOWN },
      );
      await sleep(ms / 20);
    }
  };
  const radius = scene.fingertipRadius;
  const poke = scene.actions.find((a) => a.kind === 'poke').target;
  const grasp = scene.actions.find((a) => a.kind === 'grasp').target;
  const depth = 0.012; // of the fingertip's lowest point below the target, as the scripted actions

  // Poke: the index comes down onto the poke target.
  await lower([poke[0] - OPEN_HALF - radius, poke[1] + radius - depth, poke[2]], 1000);
  const poked = await until('a force on the server', async () => {
    const s = await status();
    return s.driven && s.contact && Math.max(...s.force) > 0.05 && Math.max(...s.newtons) > 0 ? s : null;
  });
  assert.ok(poked.force[1] > 0.05 || poked.force[2] > 0.05, `the index or the middle presses: ${poked.force}`);
  await until('the page to show the force', () => page.evaluate(() => Math.max(...vrdeform.state.force) > 0.05));
  await until('a controller pulse (no glove)', () => page.evaluate(() => vrdeform.state.pulses > 0));

  // Up and over to the ridge, then down and close the trigger: a pinch grasp.
  await lower([grasp[0], grasp[1] + 0.05, grasp[2]], 300);
  await lower([grasp[0], grasp[1] + radius - depth, grasp[2]], 600);
  // Closing slowly: a grasp starts in a step where both fingertips touched and the gap shrinks.
  for (let k = 1; k <= 30; ++k) {
    await page.evaluate((v) => __xrDevice.controllers.right.updateButtonValue('trigger', v), k / 30);
    await sleep(50);
  }
  const held = await until('a grasp on the server', async () => {
    const s = await status();
    return s.grasping ? s : null;
  }).catch(async (e) => assert.fail(`${e.message}: ${JSON.stringify(await status())}`));
  assert.ok(held.driven);
  await until('the page to show the grasp', () => page.evaluate(() => vrdeform.state.grasping));

  assert.deepEqual(errors, [], `page errors: ${errors.join('\n')}`);
  const stats = (await status()).stats;
  assert.equal(stats.messagesRejected, 0, 'the page sends only valid messages');
  assert.ok(stats.inputs > 50, `inputs: ${stats.inputs}`);

  await stop();
});

// `serve --tls`: HTTPS and WSS with the self-signed certificate it made, which Chromium is told to
// trust by the public-key hash the server printed (as a headset's user accepts it once): a secure
// context, the scene over WSS and an immersive-vr session.
test('the VR page over TLS: a secure context, the scene over WSS, immersive VR', { timeout: 150000 }, async (t) => {
  const certs = mkdtempSync(path.join(tmpdir(), 'vrdeform-tls-'));
  t.after(() => rmSync(certs, { recursive: true, force: true }));
  const trusted = (output) => {
    const spki = output.match(/--ignore-certificate-errors-spki-list=(\S+)/);
    assert.ok(spki, `no public-key hash printed:\n${output}`);
    return [spki[0]];
  };
  const { base, browser, stop } = await serveAndBrowse(t, ['--tls', '--tls-dir', certs], trusted);
  assert.match(base, /^https:/);
  const { page, errors } = await headsetPage(browser);
  await page.goto(base);
  assert.equal(await page.evaluate(() => window.isSecureContext), true);
  await until('the scene and mesh frames over WSS', () => page.evaluate(() => vrdeform.state.framesReceived > 3), 30000);
  assert.equal(await page.evaluate(() => vrdeform.state.scene.name), 'liver');
  await page.click('#VRButton');
  await until('an immersive-vr session', () => page.evaluate(() => vrdeform.state.xrPresenting && vrdeform.state.xrFrames > 10));
  assert.deepEqual(errors, [], `page errors: ${errors.join('\n')}`);
  await stop();
});

// The desktop page: the force panel is not under the info box, and a left press on the body pokes
// it with the mouse (the server reports the index's force) until the button is released.
test('the desktop page: the force panel in view, poking with the mouse', { timeout: 150000 }, async (t) => {
  const { base, browser, status, stop } = await serveAndBrowse(t);
  const page = browser.pages()[0] || (await browser.newPage());
  const errors = [];
  page.on('pageerror', (e) => errors.push(String(e)));
  await page.goto(base);
  await until('the scene and mesh frames', () => page.evaluate(() => vrdeform.state.framesReceived > 3), 30000);

  const [px, py] = await page.evaluate(() => vrdeform.screenOf(vrdeform.panelCentre()));
  const box = await page.evaluate(() => {
    const r = document.getElementById('overlay').getBoundingClientRect();
    return { left: r.left, right: r.right, top: r.top, bottom: r.bottom };
  });
  assert.ok(px < box.left || px > box.right || py < box.top || py > box.bottom,
            `the force panel (${px}, ${py}) is under the info box ${JSON.stringify(box)}`);

  // The middle of the body's bounds on screen: the ray meets the body there.
  const [x, y] = await page.evaluate(() => {
    const b = vrdeform.state.scene.bodies[0];
    return vrdeform.screenOf(b.min.map((v, k) => (v + b.max[k]) / 2));
  });
  await page.mouse.move(x, y);
  await page.mouse.down();
  const pressed = await until('a force from the mouse poke', async () => {
    const s = await status();
    return s.driven && s.force[1] > 0.05 ? s : null;
  }).catch(async (e) => assert.fail(`${e.message}: ${JSON.stringify(await status())}`));
  assert.ok(pressed.newtons[1] > 0, `index newtons ${pressed.newtons}`);
  assert.equal(await page.evaluate(() => vrdeform.state.mousePokes), 1);
  await page.mouse.up();
  await until('the force to go once released', async () => (await status()).force[1] < 0.01);
  assert.deepEqual(errors, [], `page errors: ${errors.join('\n')}`);
  await stop();
});

// `vrdeform study run --vr`: participant 1 of a two-condition study walked through it in the
// emulated headset: each trial's Start, the questionnaire after each condition and the rest's
// Continue pressed on the study board with the controller's ray (trigger) in the first part and
// a tracked hand's (pinch) in the second; the final questions
// (a comparison and a free-text item) on the desktop form once out of VR. The answers in the
// participant's folder are the ones given.
test('a study on the VR page: trials, questionnaires and a rest with the controller, the last on the form', { timeout: 170000 }, async (t) => {
  const work = mkdtempSync(path.join(tmpdir(), 'vrdeform-study-'));
  t.after(() => rmSync(work, { recursive: true, force: true }));
  const studyFile = path.join(work, 'study.toml');
  writeFileSync(
    studyFile,
    `format = 1
name = "vr page"
trials = 1
rest = 1.0
points = 5
[[condition]]
name = "A"
scene = "liver"
[[condition]]
name = "B"
scene = "liver"
force = "baseline"
[[task]]
name = "poke"
instructions = "Press the liver."
seconds = 0.5
[[question]]
id = "H1"
dimension = "haptic"
text = "The force grew as I pressed."
[[question]]
id = "V1"
dimension = "visual"
text = "The liver looked soft."
[[comparison]]
id = "D1"
text = "Which felt more real?"
[[free_text]]
id = "F1"
text = "Anything else?"
after = "study"
`,
  );
  const data = path.join(work, 'data');
  const command = ['study', 'run', studyFile, data, '--participant', '1', '--vr'];
  const { base, browser, output, exited } = await serveAndBrowse(t, [], () => [], command);
  const { page, errors } = await headsetPage(browser);
  await page.goto(base);
  await until('the study panel', () => page.evaluate(() => vrdeform.state.study && vrdeform.state.framesReceived > 0), 30000);
  await page.click('#VRButton');
  await until('an immersive-vr session', () => page.evaluate(() => vrdeform.state.xrPresenting && vrdeform.state.xrFrames > 10));

  const step = () => page.evaluate(() => vrdeform.state.study);
  // Points the right controller at a board button and pulls the trigger.
  // Points the right controller's or tracked hand's target ray at a board button (`input`:
  // 'controller' or 'hand') and pulls the trigger or pinches.
  const press = async (input, action, item, value) => {
    const aim = await until(`the board's ${action} button`, () =>
      page.evaluate(([a, i, v]) => vrdeform.aimAtButton(a, i ?? undefined, v ?? undefined), [action, item, value]));
    await page.evaluate(
      ({ aim, input }) => {
        __xrDevice.primaryInputMode = input;
        const c = input === 'hand' ? __xrDevice.hands.right : __xrDevice.controllers.right;
        c.position.set(...aim.position);
        c.quaternion.set(...aim.quaternion);
      },
      { aim, input },
    );
    // Each change is seen by an XR frame before the next: the select fires on the frame the
    // trigger goes down (or the pinch closes), with the pose set before it.
    const frames = async () => {
      const n = await page.evaluate(() => vrdeform.state.xrFrames);
      await until('two XR frames', () => page.evaluate((n) => vrdeform.state.xrFrames >= n + 2, n));
    };
    const select = (input, value) =>
      page.evaluate(
        ([input, value]) =>
          input === 'hand'
            ? __xrDevice.hands.right.updatePinchValue(value)
            : __xrDevice.controllers.right.updateButtonValue('trigger', value),
        [input, value],
      );
    await frames();
    await select(input, 1);
    await frames();
    await select(input, 0);
    await frames();
  };
  const waitFor = (what, check) =>
    until(what, async () => {
      const s = await step();
      return s && check(s) ? s : null;
    }, 30000).catch(async (e) => {
      const seen = await page.evaluate(() => ({ study: vrdeform.state.study, sent: vrdeform.study.sent }));
      assert.fail(`${e.message}: the page has ${JSON.stringify(seen)}; the server said:\n${output()}`);
    });

  const pressed = [];
  for (let part = 1; part <= 2; ++part) {
    const input = part === 1 ? 'controller' : 'hand'; // the second part with a tracked hand's pinch
    await waitFor(`part ${part}'s trial`, (s) => s.step === 'trial' && !s.started && s.title.startsWith(`Part ${part} `));
    await press(input, 'start');
    // (The half-second trial may be over by the time the page is asked.)
    await waitFor(`part ${part}'s trial to start`, (s) => (s.step === 'trial' && s.started) || s.step === 'questions');
    const asked = await waitFor(`part ${part}'s questions`, (s) => s.step === 'questions');
    assert.deepEqual(asked.items.map((i) => i.text), ['The force grew as I pressed.', 'The liver looked soft.']);
    const answers = [part + 1, 5 - part]; // 2, 4 then 3, 3
    await press(input, 'rate', 0, answers[0]);
    if (part === 1) {
      // A reply the page never sends, from another connection: a rating off the scale. Refused,
      // with the reason on the panel; nothing is written, the rating already given stays, and the
      // participant goes on.
      await page.evaluate(async (id) => {
        const ws = new WebSocket(`ws://${location.host}/ws`);
        await new Promise((resolve) => (ws.onopen = resolve));
        ws.send(JSON.stringify({ type: 'study', panel: id, action: 'submit', ratings: [9, 1], texts: [] }));
        await new Promise((resolve) => setTimeout(resolve, 300));
        ws.close();
      }, asked.id);
      const refused = await waitFor('the refusal on the panel', (s) => s.step === 'questions' && s.error);
      assert.equal(refused.error, 'answer to H1: 9 is not on the scale 1..5');
      assert.ok(!existsSync(path.join(data, 'P1', 'answers.csv')), 'nothing written for a refused answer');
      assert.deepEqual(await page.evaluate(() => vrdeform.study.ratings), [answers[0], null]);
    }
    await press(input, 'rate', 1, answers[1]);
    await until('the board to show the ratings', () => page.evaluate(() => vrdeform.study.ratings.every((v) => v !== null)));
    await press(input, 'submit');
    pressed.push(answers);
    if (part === 1) {
      await waitFor('the rest', (s) => s.step === 'rest');
      await sleep(1200); // Continue is offered once the rest is over
      await press(input, 'continue');
    }
  }
  const last = await waitFor('the final questions', (s) => s.step === 'questions' && s.items.length === 2);
  assert.deepEqual(last.items.map((i) => i.rated), [true, false]);
  assert.deepEqual([last.items[0].lowAnchor, last.items[0].highAnchor], ['part 1', 'part 2']);
  // The last questions on the desktop form (a free-text item is typed there): out of VR, the form
  // shows the step.
  await page.evaluate(() => document.getElementById('VRButton').click()); // under iwer's overlay
  await until('the session to end', () => page.evaluate(() => !vrdeform.state.xrPresenting));
  await page.waitForSelector('#study:not([hidden]) textarea');
  assert.equal(await page.isDisabled('#study button[data-action=submit]'), true, 'Submit waits for the rating');
  await page.check('#study input[name=item0][value="-2"]');
  await page.fill('#study textarea', 'smooth, then "firm"');
  await page.click('#study button[data-action=submit]');
  await waitFor('the end', (s) => s.step === 'done');
  const { code } = await exited;
  assert.equal(code, 0, output());

  // P1's order is A then B (Latin square row 1); the answers are the ones pressed.
  const folder = path.join(data, 'P1');
  const answers = readFileSync(path.join(folder, 'answers.csv'), 'utf8');
  assert.match(answers, new RegExp(`A,H1,${pressed[0][0]}\\n`));
  assert.match(answers, new RegExp(`A,V1,${pressed[0][1]}\\n`));
  assert.match(answers, new RegExp(`B,H1,${pressed[1][0]}\\n`));
  assert.match(answers, new RegExp(`B,V1,${pressed[1][1]}\\n`));
  assert.match(readFileSync(path.join(folder, 'comparisons.csv'), 'utf8'), /D1,-2\n/);
  assert.deepEqual(JSON.parse(readFileSync(path.join(folder, 'free_text.json'), 'utf8')), [
    { item: 'F1', text: 'smooth, then "firm"' },
  ]);
  // Each trial recorded its length in steps (0.5 s at the liver's 60 Hz) and its signal.
  for (const [position, condition] of [[1, 'A'], [2, 'B']]) {
    const trial = path.join(folder, 'trials', `${position}-1-1`);
    const record = JSON.parse(readFileSync(path.join(trial, 'trial.json'), 'utf8'));
    assert.equal(record.condition, condition);
    assert.equal(record.steps, 30);
    // The header, a row per step, and the release's row of zeros at the end.
    assert.equal(readFileSync(path.join(trial, 'forces.csv'), 'utf8').trim().split('\n').length, 32);
  }
  assert.deepEqual(errors, [], `page errors: ${errors.join('\n')}`);
});
