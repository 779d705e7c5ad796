#pragma once
// The VR page's wire protocol (docs/vr.md#protocol): the binary messages the server sends
// (topology once per connection, then frames of quantised positions and the haptic state) and the
// JSON messages a page sends back. The JavaScript side (web/public/protocol.js) keeps to the same
// layouts; every offset here is a byte offset, every number little-endian.

#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "vrdeform/scene/view_mesh.h"
#include "vrdeform/web/xr_hand.h"

namespace vrd::vr {

inline constexpr std::uint32_t kMagic = 0x31445256;  ///< the bytes "VRD1"

enum class MessageKind : std::uint16_t { Topology = 1, Frame = 2 };

// Every binary message starts with: u32 magic, u16 kind, u16 reserved (0).
inline constexpr std::size_t kCommonHeaderBytes = 8;

// Topology: common header; u32 body count at 8; then per body 16 bytes (u32 vertex count, u32
// triangle count, u32 kind (0 soft, 1 cloth), u32 reserved); then each body's triangles as u32
// vertex indices, 3 per triangle.
inline constexpr std::size_t kTopologyHeaderBytes = 12;
inline constexpr std::size_t kTopologyBodyBytes = 16;

// Frame: a fixed header, then one block per body whose positions changed since this viewer's
// previous frame.
namespace frame {
inline constexpr std::size_t kNumber = 8;         ///< u32 frame number (server-wide, +1 per snapshot sent)
inline constexpr std::size_t kBlocks = 12;        ///< u32 body blocks that follow the header
inline constexpr std::size_t kStep = 16;          ///< u64 simulation step of the snapshot
inline constexpr std::size_t kTime = 24;          ///< f64 simulated time (s)
inline constexpr std::size_t kForce = 32;         ///< f32[5] per finger force, normalised [0, 1]
inline constexpr std::size_t kNewtons = 52;       ///< f32[5] per finger contact force (N)
inline constexpr std::size_t kPaper = 72;         ///< f32 Algorithm 2's value for the hand
inline constexpr std::size_t kFlags = 76;         ///< u32: see Flag
inline constexpr std::size_t kRadius = 80;        ///< f32 fingertip radius (m); 0 without a hand
inline constexpr std::size_t kFingertips = 84;    ///< f32[5][3] fingertip centres (m)
inline constexpr std::size_t kStepWallMs = 144;   ///< f32 wall time of the step (ms)
inline constexpr std::size_t kHeaderBytes = 152;  ///< 148..151 reserved (0)
// A body block: u32 body index, u32 vertex count, f32[3] origin, f32[3] scale, then u16[3] per
// vertex (position = origin + q * scale, per axis), zero-padded to a multiple of 4 bytes.
inline constexpr std::size_t kBlockHeaderBytes = 32;
}  // namespace frame

/// Bits of the frame's flags word. Bits 8-12: the hand has finger 0-4 (thumb .. little).
enum Flag : std::uint32_t {
  kGrasping = 1u << 0,  ///< a grasp holds a body
  kContact = 1u << 1,   ///< a finger touches or a grasp holds
  kDriven = 1u << 2,    ///< a viewer's input drives the hand (else it waits parked)
  kGlove = 1u << 3,     ///< a glove receives the forces (pages then leave the controllers still)
};
inline constexpr int kFingerFlagShift = 8;

/// The topology message for these meshes (in order).
std::vector<std::uint8_t> encodeTopology(std::span<const ViewMesh> meshes);

/// A frame's header for `snapshot`; the caller fills in kBlocks per viewer (setBlockCount).
std::array<std::uint8_t, frame::kHeaderBytes> encodeFrameHeader(const Snapshot& snapshot, std::uint32_t number,
                                                                std::uint32_t flags);
void setBlockCount(std::span<std::uint8_t, frame::kHeaderBytes> header, std::uint32_t blocks);

/// The box positions are quantised in, and the values last sent. The box is kept while the body
/// stays inside it, and a value is resent only once it moves by more than one quantum, so a body
/// at rest (float rounding jitters it far below a quantum) encodes to the same bytes frame after
/// frame and is left out of the frames.
struct QuantBox {
  Vec3 origin = Vec3::Zero();
  Vec3 scale = Vec3::Zero();  ///< metres per unit; (extent of the box) / 65535
  bool valid = false;
  std::vector<std::uint16_t> sent;  ///< the last block's values, 3 per position (empty: none yet)
};

/// A body block of `positions` (quantised in `box`, which is refitted first when a position lies
/// outside it: the body's bounds grown by half their size, at least 1 cm, on every side): within
/// half a quantum, or within one and a half where the value last sent is kept. Non-finite
/// positions quantise to the box's origin. Returns the block's bytes.
std::vector<std::uint8_t> encodeBodyBlock(std::uint32_t body, std::span<const Vec3> positions, QuantBox& box);

/// What a participant did on a study's panel (`vrdeform study run --vr`, docs/vr.md#study).
struct StudyReply {
  enum class Action { Start, Continue, Submit, Retry };
  std::uint64_t panel = 0;  ///< the panel it answers (the server's "id"): a reply to an older one is stale
  Action action = Action::Start;
  std::vector<int> ratings;        ///< Submit: per rated item, in the panel's order
  std::vector<std::string> texts;  ///< Submit: per free-text item, in the panel's order
};
inline constexpr std::size_t kMaxStudyItems = 256;       ///< ratings or texts in one reply
inline constexpr std::size_t kMaxStudyTextBytes = 4000;  ///< of one free-text answer

/// What a page sends (docs/vr.md#client-messages).
struct ClientMessage {
  enum class Type { Hello, Input, Ping, Study };
  Type type = Type::Hello;
  XrInput input;        ///< Input
  double pingTime = 0;  ///< Ping: echoed back in the pong
  std::string client;   ///< Hello: the page's name for itself (at most 64 characters)
  StudyReply study;     ///< Study
};

/// Largest nesting of JSON arrays and objects accepted (the deepest real message has 3).
inline constexpr int kMaxJsonDepth = 8;

/// Parses and validates a text message. Throws vrd::Error with the reason (malformed JSON, too
/// deep, unknown or missing type, a field of the wrong type, a non-finite or out-of-range number).
ClientMessage parseClientMessage(std::string_view text);

/// The "scene" message sent first to every viewer: names, kinds and sizes of the bodies, where
/// each one's top is, the hand and the frame rate.
std::string sceneMessage(const BuiltScene& scene, std::span<const ViewMesh> meshes, double frameRate);

}  // namespace vrd::vr
