// A study's panel on the VR page (`vrdeform study run --vr`, docs/vr.md#study): the server's
// "study" message says which step the participant is at (a trial's instructions and Start, a
// questionnaire, a rest, the end); the page shows it on a board in VR, pressed with the
// controller's or the hand's ray (the session's select), and as a form on the desktop, and sends
// back what the participant did: {type: 'study', panel, action, ratings, texts}.

import * as THREE from 'three';

const WIDTH = 1024; // canvas pixels; the board is BOARD_WIDTH metres wide
const BOARD_WIDTH = 0.5;
const MARGIN = 32;
const ROW = 96; // per rated item: its text and its scale's buttons
const TEXT_ROW = 56; // per free-text item (answered on the desktop form only)
const BUTTON_H = 44;

export function createStudyPanel(send) {
  const canvas = document.createElement('canvas');
  canvas.width = WIDTH;
  canvas.height = 512;
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  const mesh = new THREE.Mesh(
    new THREE.PlaneGeometry(1, 1),
    new THREE.MeshBasicMaterial({ map: texture, transparent: true, side: THREE.DoubleSide }),
  );
  mesh.scale.set(BOARD_WIDTH, (BOARD_WIDTH * canvas.height) / WIDTH, 1);
  mesh.visible = false;
  const form = document.createElement('div');
  form.id = 'study';
  form.hidden = true;
  document.body.appendChild(form);

  const panel = { mesh, form, message: null, ratings: [], texts: [], buttons: [], drawn: '', restEnds: 0, sent: 0,
                  continueButton: null };

  const reply = (action) => {
    const m = panel.message;
    const answers = action === 'submit' ? { ratings: panel.ratings, texts: panel.texts } : {};
    send({ type: 'study', panel: m.id, action, ...answers });
    panel.sent++;
  };
  const complete = () => panel.ratings.every((v) => v !== null);
  const restLeft = () => Math.max(0, (panel.restEnds - performance.now()) / 1000);

  // The board's buttons for the step, {x, y, w, h, label, action, item, value, enabled}.
  function layout(m) {
    const buttons = [];
    let y = MARGIN + 110;
    const wide = (label, action, enabled = true) =>
      buttons.push({ x: WIDTH / 2 - 160, y, w: 320, h: 64, label, action, enabled });
    if (m.step === 'trial' && !m.started) wide('Start', 'start');
    else if (m.step === 'failed') wide('Run the trial again', 'retry');
    else if (m.step === 'rest') wide('Continue', 'continue', restLeft() <= 0);
    else if (m.step === 'questions') {
      let r = 0;
      for (const item of m.items) {
        if (!item.rated) {
          y += TEXT_ROW;
          continue;
        }
        const n = item.high - item.low + 1;
        const w = Math.min(64, (WIDTH - 2 * MARGIN - 320) / n - 8);
        const x0 = WIDTH / 2 - (n * (w + 8)) / 2;
        for (let v = item.low; v <= item.high; ++v)
          buttons.push({ x: x0 + (v - item.low) * (w + 8), y: y + 38, w, h: BUTTON_H, label: String(v),
                         action: 'rate', item: r, value: v, enabled: true });
        y += ROW;
        ++r;
      }
      y += 16;
      wide('Submit', 'submit', complete());
    }
    return { buttons, height: Math.max(y + 100, 320) };
  }

  function draw(progress) {
    const m = panel.message;
    const key = JSON.stringify([m.id, panel.ratings, Math.ceil(restLeft()), Math.round(100 * progress)]);
    if (key === panel.drawn) return;
    panel.drawn = key;
    const { buttons, height } = layout(m);
    panel.buttons = buttons;
    if (canvas.height !== height) {
      canvas.height = height;
      mesh.scale.set(BOARD_WIDTH, (BOARD_WIDTH * height) / WIDTH, 1);
    }
    const g = canvas.getContext('2d');
    g.fillStyle = 'rgba(20, 24, 32, 0.92)';
    g.fillRect(0, 0, WIDTH, height);
    g.textBaseline = 'middle';
    // A line of text in at most `room` pixels: its font shrunk to 60% first, then cut.
    const text = (s, x, y, size, colour = '#e0e6f0', align = 'left', room = WIDTH - 2 * MARGIN) => {
      g.fillStyle = colour;
      g.textAlign = align;
      let t = String(s);
      for (let px = size; ; px -= 1) {
        g.font = `${px}px sans-serif`;
        if (g.measureText(t).width <= room || px <= 0.6 * size) break;
      }
      while (t.length > 4 && g.measureText(`${t}…`).width > room) t = t.slice(0, -2);
      g.fillText(t === String(s) ? t : `${t}…`, x, y);
    };
    text(m.title, MARGIN, MARGIN + 20, 34);
    if (m.error) text(m.error, MARGIN, MARGIN + 60, 24, '#ff7a5c');
    else if (m.text) text(m.text, MARGIN, MARGIN + 60, 26, '#9aa4b4');
    if (m.step === 'trial' && m.started) {
      g.fillStyle = '#2f3644';
      g.fillRect(MARGIN, MARGIN + 120, WIDTH - 2 * MARGIN, 28);
      g.fillStyle = '#4fc3f7';
      g.fillRect(MARGIN, MARGIN + 120, (WIDTH - 2 * MARGIN) * progress, 28);
    }
    if (m.step === 'rest') text(`${Math.ceil(restLeft())} s`, WIDTH / 2, MARGIN + 90, 28, '#9aa4b4', 'center');
    if (m.step === 'questions') {
      let y = MARGIN + 110;
      for (const item of m.items) {
        if (!item.rated) {
          text(`${item.text} (on the desktop form; left empty here)`, MARGIN, y + 20, 22, '#9aa4b4');
          y += TEXT_ROW;
          continue;
        }
        text(item.text, MARGIN, y + 14, 24);
        const row = buttons.filter((b) => b.action === 'rate' && b.y === y + 38);
        const last = row[row.length - 1];
        const room = row[0].x - 12 - MARGIN;
        text(item.lowAnchor, row[0].x - 12, y + 38 + BUTTON_H / 2, 20, '#9aa4b4', 'right', room);
        text(item.highAnchor, last.x + last.w + 12, y + 38 + BUTTON_H / 2, 20, '#9aa4b4', 'left', room);
        y += ROW;
      }
    }
    for (const b of buttons) {
      const chosen = b.action === 'rate' && panel.ratings[b.item] === b.value;
      g.fillStyle = !b.enabled ? '#3a404c' : chosen ? '#ff9800' : '#4a78c0';
      g.fillRect(b.x, b.y, b.w, b.h);
      text(b.label, b.x + b.w / 2, b.y + b.h / 2, b.action === 'rate' ? 24 : 30, b.enabled ? '#ffffff' : '#8a909c', 'center');
    }
    texture.needsUpdate = true;
  }

  // The desktop form: the same step as HTML controls.
  function buildForm() {
    const m = panel.message;
    form.replaceChildren();
    panel.continueButton = null;
    const add = (tag, props = {}, parent = form) => parent.appendChild(Object.assign(document.createElement(tag), props));
    add('h2', { textContent: m.title });
    if (m.text) add('p', { textContent: m.text });
    if (m.error) add('p', { className: 'error', textContent: m.error });
    const button = (label, action, enabled = () => true) => {
      const b = add('button', { textContent: label, disabled: !enabled() });
      b.dataset.action = action;
      b.onclick = () => reply(action);
      return b;
    };
    if (m.step === 'trial' && !m.started) button('Start', 'start');
    if (m.step === 'failed') button('Run the trial again', 'retry');
    if (m.step === 'rest') panel.continueButton = button('Continue', 'continue', () => restLeft() <= 0);
    if (m.step !== 'questions') return;
    let r = 0, t = 0;
    for (const item of m.items) {
      const p = add('fieldset');
      add('legend', { textContent: item.text }, p);
      if (!item.rated) {
        const k = t++;
        const area = add('textarea', { rows: 3, maxLength: 4000, value: panel.texts[k] }, p);
        area.oninput = () => (panel.texts[k] = area.value);
        continue;
      }
      const k = r++;
      add('span', { className: 'anchor', textContent: item.lowAnchor }, p);
      for (let v = item.low; v <= item.high; ++v) {
        const label = add('label', {}, p);
        const input = add('input', { type: 'radio', name: `item${k}`, value: String(v), checked: panel.ratings[k] === v }, label);
        input.onchange = () => {
          panel.ratings[k] = v;
          submit.disabled = !complete();
        };
        label.append(String(v));
      }
      add('span', { className: 'anchor', textContent: item.highAnchor }, p);
    }
    const submit = button('Submit', 'submit', complete);
  }

  return {
    mesh,
    panel,
    // A "study" message from the server.
    show(m) {
      // The same questions again (a refusal said on the panel) keep what was answered.
      const was = panel.message;
      const fresh =
        !was || was.step !== m.step || was.title !== m.title || JSON.stringify(was.items) !== JSON.stringify(m.items);
      panel.message = m;
      if (fresh && m.step === 'questions') {
        panel.ratings = m.items.filter((i) => i.rated).map(() => null);
        panel.texts = m.items.filter((i) => !i.rated).map(() => '');
      }
      if (m.step === 'rest') panel.restEnds = performance.now() + 1000 * m.seconds;
      panel.drawn = '';
      buildForm();
    },
    // Each frame: the board (in VR) or the form (on the desktop), the trial's progress from the
    // simulated time.
    update(presenting, time) {
      const m = panel.message;
      mesh.visible = !!m && presenting;
      form.hidden = !m || presenting;
      if (!m) return;
      if (panel.continueButton) panel.continueButton.disabled = restLeft() > 0;
      if (presenting) draw(m.step === 'trial' && m.started && m.seconds > 0 ? Math.min(1, time / m.seconds) : 0);
    },
    // A select (trigger or pinch) along `ray` (world coordinates): presses the board's button there.
    select(ray) {
      if (!mesh.visible) return false;
      const hit = new THREE.Raycaster(ray.origin, ray.direction).intersectObject(mesh, false)[0];
      if (!hit || !hit.uv) return false;
      const x = hit.uv.x * WIDTH, y = (1 - hit.uv.y) * canvas.height;
      const b = panel.buttons.find((b) => x >= b.x && x <= b.x + b.w && y >= b.y && y <= b.y + b.h);
      if (!b || !b.enabled) return true;
      if (b.action === 'rate') {
        panel.ratings[b.item] = b.value;
        panel.drawn = '';
      } else {
        reply(b.action);
      }
      return true;
    },
    // Where a board's button is (world coordinates), for tests: {action, item, value} picks it.
    buttonCentre(action, item, value) {
      const b = panel.buttons.find((b) => b.action === action && (item === undefined || b.item === item) &&
                                          (value === undefined || b.value === value));
      if (!b) return null;
      const u = (b.x + b.w / 2) / WIDTH, v = 1 - (b.y + b.h / 2) / canvas.height;
      return mesh.localToWorld(new THREE.Vector3(u - 0.5, v - 0.5, 0)).toArray();
    },
  };
}
