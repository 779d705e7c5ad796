// The vrdeform VR page: draws the bodies `vrdeform serve` streams, in a desktop browser (mouse
// orbit) or in an immersive-vr session, and sends the tracked controller or hand back so that the
// user pokes and grasps (docs/vr.md). Without a glove, the controller vibrates with the force.

import * as THREE from 'three';
import { OrbitControls } from 'three/addons/controls/OrbitControls.js';
import { VRButton } from 'three/addons/webxr/VRButton.js';
import * as wire from './protocol.js';
import { createStudyPanel } from './study.js';

// Where the first body's top is placed in VR, from the head at the session's first frame: 30 cm
// below it and 40 cm ahead (horizontally), on a table in front of the user, standing or seated. A
// study's board stands behind it, a little below the eyes, facing the head.
const BELOW_HEAD = 0.3;
const AHEAD_OF_HEAD = 0.4;
const BOARD_AHEAD = 0.6;
const BOARD_BELOW_HEAD = 0.05;
const BODY_COLOURS = [0xb8432f, 0xd9a441, 0x6a8fd0, 0x8fbf5a, 0xa070c0];
const TIP_COLOUR = new THREE.Color(0x4fc3f7);
const PRESS_COLOUR = new THREE.Color(0xff9800);
const HAPTIC_INTERVAL_MS = 25; // one pulse per this, lasting a little longer, while there is force

// What the page knows, for the read-out and for tests (window.vrdeform.state).
const state = {
  connected: false,
  scene: null,
  framesReceived: 0,
  blocksApplied: 0,
  step: 0,
  time: 0,
  study: null, // the study's panel message (`vrdeform study run --vr`), else null
  force: [0, 0, 0, 0, 0],
  newtons: [0, 0, 0, 0, 0],
  grasping: false,
  contact: false,
  driven: false,
  glove: false,
  xrPresenting: false,
  xrFrames: 0,
  inputsSent: 0,
  mousePokes: 0,
  pulses: 0,
  lastError: null,
};

// --- Three.js scene -----------------------------------------------------------------------------

const renderer = new THREE.WebGLRenderer({ antialias: true });
renderer.setPixelRatio(window.devicePixelRatio);
renderer.setSize(window.innerWidth, window.innerHeight);
renderer.xr.enabled = true;
document.body.appendChild(renderer.domElement);
document.body.appendChild(VRButton.createButton(renderer, { optionalFeatures: ['local-floor', 'hand-tracking'] }));

const scene = new THREE.Scene();
scene.background = new THREE.Color(0x20242c);
scene.add(new THREE.HemisphereLight(0xe8eef8, 0x404048, 1.6));
const sun = new THREE.DirectionalLight(0xffffff, 2.2);
sun.position.set(0.6, 1.5, 0.8);
scene.add(sun);

// Everything in scene coordinates hangs off this root; in VR it moves the bodies onto the table.
const root = new THREE.Group();
scene.add(root);
const ground = new THREE.Mesh(
  new THREE.CircleGeometry(0.5, 64),
  new THREE.MeshStandardMaterial({ color: 0x6b6f76, roughness: 0.9 }),
);
ground.rotation.x = -Math.PI / 2;
root.add(ground);

const camera = new THREE.PerspectiveCamera(50, window.innerWidth / window.innerHeight, 0.01, 20);
camera.position.set(0, 0.3, 0.5);
const controls = new OrbitControls(camera, renderer.domElement);
controls.target.set(0, 0.05, 0);
controls.update();

let bodies = []; // per body: {mesh, positions (Float32Array), dirty}
let tips = []; // one sphere per finger (hidden for fingers the hand lacks)
const panel = makePanel();
root.add(panel.mesh);
const study = createStudyPanel((m) => socket && socket.readyState === WebSocket.OPEN && socket.send(JSON.stringify(m)));
scene.add(study.mesh);
// The controllers' rays, shown while the study's board waits for a press.
const rays = [0, 1].map((i) => {
  const controller = renderer.xr.getController(i);
  const line = new THREE.Line(
    new THREE.BufferGeometry().setFromPoints([new THREE.Vector3(0, 0, 0), new THREE.Vector3(0, 0, -1.5)]),
    new THREE.LineBasicMaterial({ color: 0x4fc3f7 }),
  );
  controller.add(line);
  scene.add(controller);
  return line;
});

function makePanel() {
  const canvas = document.createElement('canvas');
  canvas.width = 512;
  canvas.height = 160;
  const texture = new THREE.CanvasTexture(canvas);
  texture.colorSpace = THREE.SRGBColorSpace;
  const mesh = new THREE.Mesh(
    new THREE.PlaneGeometry(0.16, 0.05),
    new THREE.MeshBasicMaterial({ map: texture, transparent: true }),
  );
  return { canvas, texture, mesh, drawn: '' };
}

// The force read-out: a bar and the newtons per finger, the grasp and the frame state.
function drawPanel() {
  const fingers = state.scene ? state.scene.fingers : [];
  const text = JSON.stringify([state.force, state.grasping, state.driven, state.connected, fingers]);
  if (text === panel.drawn) return;
  panel.drawn = text;
  const g = panel.canvas.getContext('2d');
  g.fillStyle = 'rgba(20, 24, 32, 0.85)';
  g.fillRect(0, 0, 512, 160);
  g.font = '22px sans-serif';
  g.fillStyle = '#e0e6f0';
  const title = !state.connected ? 'disconnected' : state.grasping ? 'grasping' : state.driven ? 'hand' : 'no hand input';
  g.fillText(`vrdeform: ${title}`, 12, 28);
  fingers.forEach((name, k) => {
    const f = wire.FINGERS.indexOf(name);
    const y = 44 + 22 * k;
    g.fillStyle = '#9aa4b4';
    g.fillText(name, 12, y + 17);
    g.fillStyle = '#2f3644';
    g.fillRect(110, y + 2, 280, 16);
    g.fillStyle = `hsl(${120 - 120 * state.force[f]}, 70%, 50%)`;
    g.fillRect(110, y + 2, 280 * state.force[f], 16);
    g.fillStyle = '#e0e6f0';
    g.fillText(`${state.newtons[f].toFixed(2)} N`, 400, y + 17);
  });
  panel.texture.needsUpdate = true;
  const overlay = document.getElementById('readout');
  if (overlay)
    overlay.textContent = `${title}; ${fingers
      .map((name) => `${name} ${state.force[wire.FINGERS.indexOf(name)].toFixed(2)}`)
      .join(', ')}`;
}

function buildScene(info, topology) {
  for (const b of bodies) {
    root.remove(b.mesh);
    b.mesh.geometry.dispose();
  }
  for (const t of tips) root.remove(t);
  bodies = topology.map((t, k) => {
    const geometry = new THREE.BufferGeometry();
    const positions = new Float32Array(3 * t.vertexCount);
    geometry.setAttribute('position', new THREE.BufferAttribute(positions, 3).setUsage(THREE.DynamicDrawUsage));
    geometry.setIndex(new THREE.BufferAttribute(t.indices, 1));
    const material = new THREE.MeshStandardMaterial({
      color: BODY_COLOURS[k % BODY_COLOURS.length],
      roughness: 0.55,
      side: t.kind === 'cloth' ? THREE.DoubleSide : THREE.FrontSide,
    });
    const mesh = new THREE.Mesh(geometry, material);
    mesh.frustumCulled = false; // the bounds change every frame
    mesh.visible = false; // until its first positions arrive
    root.add(mesh);
    return { mesh, positions, dirty: false };
  });
  const radius = info.fingertipRadius || 0.009;
  tips = wire.FINGERS.map(() => {
    const s = new THREE.Mesh(
      new THREE.SphereGeometry(radius, 24, 16),
      new THREE.MeshStandardMaterial({ color: TIP_COLOUR, roughness: 0.4 }),
    );
    s.visible = false;
    root.add(s);
    return s;
  });
  const first = info.bodies[0];
  if (first) {
    const top = new THREE.Vector3(...first.top);
    const centre = new THREE.Vector3(...first.min).add(new THREE.Vector3(...first.max)).multiplyScalar(0.5);
    // The body and the force panel 6 cm above its top, both in view.
    panel.mesh.position.copy(top).add(new THREE.Vector3(0, 0.06, 0));
    controls.target.copy(centre).lerp(panel.mesh.position, 0.25);
    camera.position.copy(controls.target).add(new THREE.Vector3(0, 0.22, 0.38));
    controls.update();
  }
  placeRoot();
}

// In VR the first body's top goes in front of the head (placeInXr); on the desktop the scene stays
// where it is.
let placedInXr = false;
function placeRoot() {
  placedInXr = false;
  root.position.set(0, 0, 0);
  root.updateMatrixWorld(true);
}

function placeInXr(frame) {
  const first = state.scene && state.scene.bodies[0];
  const viewer = first && frame.getViewerPose(renderer.xr.getReferenceSpace());
  if (!viewer) return;
  const head = new THREE.Vector3().copy(viewer.transform.position);
  const q = viewer.transform.orientation;
  const ahead = new THREE.Vector3(0, 0, -1).applyQuaternion(new THREE.Quaternion(q.x, q.y, q.z, q.w));
  ahead.y = 0;
  if (ahead.lengthSq() < 1e-6) ahead.set(0, 0, -1);
  ahead.normalize();
  const table = head.addScaledVector(ahead, AHEAD_OF_HEAD).add(new THREE.Vector3(0, -BELOW_HEAD, 0));
  root.position.copy(table).sub(new THREE.Vector3(...first.top));
  root.updateMatrixWorld(true);
  const eye = new THREE.Vector3().copy(viewer.transform.position);
  study.mesh.position.copy(eye).addScaledVector(ahead, BOARD_AHEAD).add(new THREE.Vector3(0, -BOARD_BELOW_HEAD, 0));
  study.mesh.lookAt(eye);
  study.mesh.updateMatrixWorld(true);
  placedInXr = true;
}

function applyFrame(buffer) {
  const frame = wire.decodeFrame(buffer);
  for (const block of frame.blocks) {
    const b = bodies[block.body];
    if (!b || block.vertexCount * 3 !== b.positions.length) throw new Error(`frame: bad block for body ${block.body}`);
    wire.applyBlock(buffer, block, b.positions);
    b.dirty = true;
    ++state.blocksApplied;
  }
  frame.fingertips.forEach((p, f) => {
    const s = tips[f];
    if (!s) return;
    s.visible = frame.present[f] && frame.driven; // parked, out of the way, while nobody drives the hand
    s.position.set(p[0], p[1], p[2]);
    s.material.color.copy(TIP_COLOUR).lerp(PRESS_COLOUR, Math.min(1, frame.force[f]));
  });
  state.framesReceived++;
  state.step = frame.step;
  state.time = frame.time;
  state.force = frame.force;
  state.newtons = frame.newtons;
  state.grasping = frame.grasping;
  state.contact = frame.contact;
  state.driven = frame.driven;
  state.glove = frame.glove;
}

// --- Poking with the mouse (desktop) -----------------------------------------------------------

// A left press on a body pokes it: the index fingertip appears touching the surface under the
// cursor and sinks in along the view ray to one fingertip radius over POKE_SECONDS, as in the
// desktop viewer; it comes back out on release. A press off the bodies orbits the camera.
const POKE_SECONDS = 0.5;
const RETRACT = 0.05; // m back along the ray on release, before the server parks the hand
const raycaster = new THREE.Raycaster();
let mousePoke = null; // { point, direction, start } in scene coordinates while pressing

function bodyUnder(event) {
  const rect = renderer.domElement.getBoundingClientRect();
  const ndc = new THREE.Vector2(
    ((event.clientX - rect.left) / rect.width) * 2 - 1,
    -((event.clientY - rect.top) / rect.height) * 2 + 1,
  );
  raycaster.setFromCamera(ndc, camera);
  const meshes = bodies.filter((b) => b.mesh.visible).map((b) => b.mesh);
  for (const m of meshes) m.geometry.computeBoundingSphere(); // the vertices move every frame
  const hit = raycaster.intersectObjects(meshes, false)[0];
  return hit ? { point: root.worldToLocal(hit.point.clone()), direction: raycaster.ray.direction.clone() } : null;
}

// The fingertips for the server: the index at `depth` past the surface along the ray, the others
// where they are (null).
function sendPoke(depth) {
  if (!socket || socket.readyState !== WebSocket.OPEN || !mousePoke || !state.scene) return;
  const r = state.scene.fingertipRadius || 0.009;
  const index = mousePoke.point.clone().addScaledVector(mousePoke.direction, depth - r);
  const tips = wire.FINGERS.map((name) => (name === 'index' ? index.toArray() : null));
  socket.send(wire.inputMessage(null, { source: 'hand', tips }));
  state.inputsSent++;
}

renderer.domElement.addEventListener(
  'pointerdown',
  (event) => {
    if (renderer.xr.isPresenting || event.button !== 0 || !state.scene) return;
    const hit = bodyUnder(event);
    if (!hit) return; // the orbit controls take it
    event.stopImmediatePropagation(); // before OrbitControls: no orbit while poking
    renderer.domElement.setPointerCapture(event.pointerId);
    mousePoke = { ...hit, start: performance.now() };
    state.mousePokes++;
  },
  { capture: true },
);
renderer.domElement.addEventListener('pointerup', () => {
  if (!mousePoke) return;
  sendPoke(-RETRACT);
  mousePoke = null;
});

function pokeStep() {
  if (!mousePoke) return;
  const r = (state.scene && state.scene.fingertipRadius) || 0.009;
  const held = (performance.now() - mousePoke.start) / 1000;
  sendPoke(r * Math.min(held / POKE_SECONDS, 1));
}

// --- The connection ----------------------------------------------------------------------------

let socket = null;
let pendingScene = null;

function connect() {
  const url = `${location.protocol === 'https:' ? 'wss' : 'ws'}://${location.host}/ws`;
  socket = new WebSocket(url);
  socket.binaryType = 'arraybuffer';
  socket.onopen = () => {
    state.connected = true;
    socket.send(JSON.stringify({ type: 'hello', client: 'vrdeform page' }));
  };
  socket.onclose = () => {
    state.connected = false;
    setTimeout(connect, 1000);
  };
  socket.onmessage = (event) => {
    try {
      if (typeof event.data === 'string') {
        const m = JSON.parse(event.data);
        if (m.type === 'scene') pendingScene = m;
        else if (m.type === 'study') study.show((state.study = m));
        else if (m.type === 'error') state.lastError = m.reason;
        return;
      }
      const kind = wire.messageKind(event.data);
      if (kind === wire.KIND_TOPOLOGY && pendingScene) {
        state.scene = pendingScene;
        buildScene(pendingScene, wire.decodeTopology(event.data));
        document.title = `vrdeform: ${pendingScene.name}`;
      } else if (kind === wire.KIND_FRAME && state.scene) {
        applyFrame(event.data);
      }
    } catch (e) {
      state.lastError = String(e);
      console.error(e);
    }
  };
}
connect();

// --- XR input and haptics ----------------------------------------------------------------------

const JOINTS = ['thumb-tip', 'index-finger-tip', 'middle-finger-tip', 'ring-finger-tip', 'pinky-finger-tip'];
let lastPulse = 0;

// The right hand if there is one, else any: the simulation has one hand.
function drivingSource(session) {
  let chosen = null;
  for (const source of session.inputSources) {
    if (!source.hand && !source.gamepad) continue;
    if (!chosen || source.handedness === 'right') chosen = source;
  }
  return chosen;
}

function toScene(p) {
  return [p.x - root.position.x, p.y - root.position.y, p.z - root.position.z];
}

function readInput(frame, space, source) {
  if (!source) return null;
  if (source.hand) {
    const tipsOut = JOINTS.map((name) => {
      const joint = source.hand.get(name);
      const pose = joint && frame.getJointPose(joint, space);
      return pose ? toScene(pose.transform.position) : null;
    });
    return { source: 'hand', tips: tipsOut };
  }
  const pose = frame.getPose(source.targetRaySpace, space);
  if (!pose) return null;
  const o = pose.transform.orientation;
  const buttons = source.gamepad ? source.gamepad.buttons : [];
  return {
    source: 'controller',
    ray: { position: toScene(pose.transform.position), orientation: [o.x, o.y, o.z, o.w] },
    trigger: buttons[0] ? buttons[0].value : 0,
    squeeze: buttons[1] ? buttons[1].value : 0,
  };
}

function sendInput(frame) {
  const session = renderer.xr.getSession();
  const space = renderer.xr.getReferenceSpace();
  if (!session || !space || !socket || socket.readyState !== WebSocket.OPEN) return;
  if (socket.bufferedAmount > 64 * 1024) return; // the network is behind: skip, never pile up
  const viewer = frame.getViewerPose(space);
  const o = viewer && viewer.transform.orientation;
  const head = viewer ? { position: toScene(viewer.transform.position), orientation: [o.x, o.y, o.z, o.w] } : null;
  const source = drivingSource(session);
  socket.send(wire.inputMessage(head, readInput(frame, space, source)));
  state.inputsSent++;
  pulse(source);
}

// Without a glove the controller's vibration mirrors the force of the hand's fingers.
function pulse(source) {
  if (state.glove || !source || !source.gamepad || !state.driven) return;
  const force = Math.max(...state.force);
  const now = performance.now();
  if (force < 0.02 || now - lastPulse < HAPTIC_INTERVAL_MS) return;
  const actuator = source.gamepad.hapticActuators && source.gamepad.hapticActuators[0];
  if (!actuator) return;
  lastPulse = now;
  actuator.pulse(Math.min(1, force), 2 * HAPTIC_INTERVAL_MS);
  state.pulses++;
}

// A select (trigger or pinch) presses the study board's button its target ray points at.
function onSelect(event) {
  const pose = event.frame.getPose(event.inputSource.targetRaySpace, renderer.xr.getReferenceSpace());
  if (!pose) return;
  const o = pose.transform.orientation;
  const direction = new THREE.Vector3(0, 0, -1).applyQuaternion(new THREE.Quaternion(o.x, o.y, o.z, o.w));
  study.select(new THREE.Ray(new THREE.Vector3().copy(pose.transform.position), direction));
}

renderer.xr.addEventListener('sessionstart', () => {
  state.xrPresenting = true;
  renderer.xr.getSession().addEventListener('select', onSelect);
  placeRoot();
});
renderer.xr.addEventListener('sessionend', () => {
  state.xrPresenting = false;
  placeRoot();
});

// --- The loop -----------------------------------------------------------------------------------

window.addEventListener('resize', () => {
  camera.aspect = window.innerWidth / window.innerHeight;
  camera.updateProjectionMatrix();
  renderer.setSize(window.innerWidth, window.innerHeight);
});

renderer.setAnimationLoop((time, frame) => {
  for (const b of bodies) {
    if (!b.dirty) continue;
    b.dirty = false;
    b.mesh.geometry.attributes.position.needsUpdate = true;
    b.mesh.geometry.computeVertexNormals();
    b.mesh.visible = true;
  }
  if (frame) {
    if (!placedInXr) placeInXr(frame);
    state.xrFrames++;
    sendInput(frame);
  } else {
    controls.update();
    pokeStep();
  }
  drawPanel();
  study.update(renderer.xr.isPresenting, state.time);
  for (const ray of rays) ray.visible = study.mesh.visible;
  renderer.render(scene, camera);
  if (window.vrdeform.afterRender) window.vrdeform.afterRender(renderer.getContext(), renderer.xr.isPresenting);
});

// For tests and the curious: the state, a hook after each render, and the scene-to-XR mapping.
window.vrdeform = {
  state,
  afterRender: null,
  toXr: (p) => [p[0] + root.position.x, p[1] + root.position.y, p[2] + root.position.z],
  vertex: (body, i) => Array.from(bodies[body].positions.subarray(3 * i, 3 * i + 3)),
  fingertips: () => tips.map((t) => (t.visible ? t.position.toArray() : null)),
  // Where a point in scene coordinates is drawn on the desktop, in CSS pixels of the page.
  screenOf: (p) => {
    const v = root.localToWorld(new THREE.Vector3(...p)).project(camera);
    const rect = renderer.domElement.getBoundingClientRect();
    return [rect.left + ((v.x + 1) / 2) * rect.width, rect.top + ((1 - v.y) / 2) * rect.height];
  },
  panelCentre: () => panel.mesh.position.toArray(),
  study: study.panel,
  // A pose 30 cm in front of a study board's button, its target ray (-z) on it: {position, quaternion}.
  aimAtButton: (action, item, value) => {
    const at = study.buttonCentre(action, item, value);
    if (!at) return null;
    const target = new THREE.Vector3(...at);
    const normal = new THREE.Vector3(0, 0, 1).applyQuaternion(study.mesh.getWorldQuaternion(new THREE.Quaternion()));
    const eye = target.clone().addScaledVector(normal, 0.3);
    const q = new THREE.Quaternion().setFromRotationMatrix(new THREE.Matrix4().lookAt(eye, target, new THREE.Vector3(0, 1, 0)));
    return { position: eye.toArray(), quaternion: q.toArray() };
  },
};
