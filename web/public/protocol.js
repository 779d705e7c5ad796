// The wire protocol of `vrdeform serve` (docs/vr.md#protocol), the page's side: decoding the
// binary topology and frame messages, and the JSON messages the page sends. Offsets are bytes,
// numbers little-endian, as in include/vrdeform/web/vr_protocol.h.

export const MAGIC = 0x31445256; // "VRD1"
export const KIND_TOPOLOGY = 1;
export const KIND_FRAME = 2;
export const FINGERS = ['thumb', 'index', 'middle', 'ring', 'little'];

export const FLAG_GRASPING = 1 << 0;
export const FLAG_CONTACT = 1 << 1;
export const FLAG_DRIVEN = 1 << 2;
export const FLAG_GLOVE = 1 << 3;
const FINGER_FLAG_SHIFT = 8;

const FRAME_HEADER_BYTES = 152;
const BLOCK_HEADER_BYTES = 32;

/** The kind of a binary message (KIND_TOPOLOGY, KIND_FRAME), or 0 when it is not one of ours. */
export function messageKind(buffer) {
  if (buffer.byteLength < 8) return 0;
  const v = new DataView(buffer);
  return v.getUint32(0, true) === MAGIC ? v.getUint16(4, true) : 0;
}

/** Topology: per body its vertex count, kind ('soft' or 'cloth') and triangle indices. */
export function decodeTopology(buffer) {
  const v = new DataView(buffer);
  const count = v.getUint32(8, true);
  const bodies = [];
  let tris = 12 + 16 * count;
  for (let b = 0; b < count; ++b) {
    const at = 12 + 16 * b;
    const vertexCount = v.getUint32(at, true);
    const triangleCount = v.getUint32(at + 4, true);
    const kind = v.getUint32(at + 8, true) === 1 ? 'cloth' : 'soft';
    const indices = new Uint32Array(3 * triangleCount);
    for (let i = 0; i < indices.length; ++i, tris += 4) indices[i] = v.getUint32(tris, true);
    bodies.push({ vertexCount, triangleCount, kind, indices });
  }
  return bodies;
}

/** A frame's header and the body blocks it holds (positions are decoded by applyBlock). */
export function decodeFrame(buffer) {
  const v = new DataView(buffer);
  const f32s = (at, n) => Array.from({ length: n }, (_, i) => v.getFloat32(at + 4 * i, true));
  const flags = v.getUint32(76, true);
  const frame = {
    number: v.getUint32(8, true),
    step: Number(v.getBigUint64(16, true)),
    time: v.getFloat64(24, true),
    force: f32s(32, 5),
    newtons: f32s(52, 5),
    paper: v.getFloat32(72, true),
    flags,
    grasping: (flags & FLAG_GRASPING) !== 0,
    contact: (flags & FLAG_CONTACT) !== 0,
    driven: (flags & FLAG_DRIVEN) !== 0,
    glove: (flags & FLAG_GLOVE) !== 0,
    present: FINGERS.map((_, f) => (flags & (1 << (FINGER_FLAG_SHIFT + f))) !== 0),
    radius: v.getFloat32(80, true),
    fingertips: FINGERS.map((_, f) => f32s(84 + 12 * f, 3)),
    stepWallMs: v.getFloat32(144, true),
    blocks: [],
  };
  const blocks = v.getUint32(12, true);
  let at = FRAME_HEADER_BYTES;
  for (let k = 0; k < blocks; ++k) {
    const vertexCount = v.getUint32(at + 4, true);
    frame.blocks.push({
      body: v.getUint32(at, true),
      vertexCount,
      origin: f32s(at + 8, 3),
      scale: f32s(at + 20, 3),
      offset: at + BLOCK_HEADER_BYTES,
    });
    at += BLOCK_HEADER_BYTES + Math.ceil((6 * vertexCount) / 4) * 4;
  }
  if (at !== buffer.byteLength) throw new Error(`frame ${frame.number}: ${buffer.byteLength} bytes, expected ${at}`);
  return frame;
}

/** Writes a block's positions (origin + q * scale per axis) into `out` (x, y, z per vertex). */
export function applyBlock(buffer, block, out) {
  const v = new DataView(buffer);
  const [ox, oy, oz] = block.origin;
  const [sx, sy, sz] = block.scale;
  for (let i = 0, at = block.offset; i < block.vertexCount; ++i, at += 6) {
    out[3 * i] = ox + v.getUint16(at, true) * sx;
    out[3 * i + 1] = oy + v.getUint16(at + 2, true) * sy;
    out[3 * i + 2] = oz + v.getUint16(at + 4, true) * sz;
  }
}

const round = (x) => Math.round(x * 1e5) / 1e5; // 10 µm: plenty, and shorter messages

function pose(position, orientation) {
  return { p: position.map(round), q: orientation.map(round) };
}

/**
 * The input message. `hand` is null (nothing tracked), {source: 'controller', ray: {position,
 * orientation}, trigger, squeeze} or {source: 'hand', tips: [5 × [x, y, z] or null]}; `head` is
 * null or {position, orientation}. Scene coordinates; orientations as [x, y, z, w].
 */
export function inputMessage(head, hand) {
  const m = { type: 'input', head: head ? pose(head.position, head.orientation) : null, hand: null };
  if (hand && hand.source === 'controller')
    m.hand = {
      source: 'controller',
      ray: pose(hand.ray.position, hand.ray.orientation),
      trigger: round(hand.trigger),
      squeeze: round(hand.squeeze),
    };
  else if (hand && hand.source === 'hand')
    m.hand = { source: 'hand', tips: hand.tips.map((t) => (t ? t.map(round) : null)) };
  return JSON.stringify(m);
}
