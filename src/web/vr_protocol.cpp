#include "vrdeform/web/vr_protocol.h"

#include <fmt/format.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <limits>
#include <nlohmann/json.hpp>

#include "vrdeform/core/json_depth.h"
#include "vrdeform/devices/haptic_output.h"
#include "vrdeform/error.h"

namespace vrd::vr {
namespace {

static_assert(std::endian::native == std::endian::little, "the wire format is little-endian, as is this machine");

using json = nlohmann::json;

template <class T>
void put(std::uint8_t* at, T value) {
  std::memcpy(at, &value, sizeof(T));
}

void putCommon(std::uint8_t* at, MessageKind kind) {
  put(at, kMagic);
  put(at + 4, std::uint16_t(kind));
  put(at + 6, std::uint16_t(0));
}

// --- Client messages ------------------------------------------------------------------------------

[[noreturn]] void bad(const std::string& what) { throw Error(what); }

// At most `max` bytes of a string from the page, cut before a character, not inside one: the
// server sends the reasons for rejecting a message back as JSON, which must be valid UTF-8 (the
// parser has checked that the whole string is).
std::string_view excerpt(std::string_view s, std::size_t max) {
  if (s.size() <= max) return s;
  while (max > 0 && (static_cast<unsigned char>(s[max]) & 0xC0) == 0x80) --max;  // a continuation byte
  return s.substr(0, max);
}

// Scene coordinates and anything else: finite and within a kilometre.
float number(const json& j, const std::string& where, float limit = 1e3f) {
  if (!j.is_number()) bad(fmt::format("{}: expected a number", where));
  const double v = j.get<double>();
  if (!std::isfinite(v) || std::abs(v) > limit) bad(fmt::format("{}: {} is out of range", where, v));
  return float(v);
}

Vec3 vec3(const json& j, const std::string& where) {
  if (!j.is_array() || j.size() != 3) bad(fmt::format("{}: expected [x, y, z]", where));
  return {number(j[0], where + "[0]"), number(j[1], where + "[1]"), number(j[2], where + "[2]")};
}

XrPose pose(const json& j, const std::string& where) {
  if (!j.is_object()) bad(fmt::format("{}: expected {{\"p\": [x, y, z], \"q\": [x, y, z, w]}}", where));
  const auto p = j.find("p"), q = j.find("q");
  if (p == j.end() || q == j.end()) bad(fmt::format("{}: needs \"p\" and \"q\"", where));
  if (!q->is_array() || q->size() != 4) bad(fmt::format("{}.q: expected [x, y, z, w]", where));
  XrPose out;
  out.position = vec3(*p, where + ".p");
  const Eigen::Quaternionf r(number((*q)[3], where + ".q[3]", 2.0f), number((*q)[0], where + ".q[0]", 2.0f),
                             number((*q)[1], where + ".q[1]", 2.0f), number((*q)[2], where + ".q[2]", 2.0f));
  const float n = r.norm();
  if (!(n > 0.9f && n < 1.1f)) bad(fmt::format("{}.q: not a unit quaternion (norm {})", where, n));
  out.orientation = r.normalized();
  return out;
}

float unitValue(const json& parent, const char* key, const std::string& where) {
  const auto it = parent.find(key);
  if (it == parent.end()) return 0.0f;
  const float v = number(*it, where + "." + key, 1.0f);
  if (v < 0.0f) bad(fmt::format("{}.{}: {} is not in [0, 1]", where, key, v));
  return v;
}

XrInput input(const json& m) {
  XrInput in;
  if (const auto head = m.find("head"); head != m.end() && !head->is_null()) in.head = pose(*head, "head");
  const auto hand = m.find("hand");
  if (hand == m.end() || hand->is_null()) return in;  // head only: nothing drives the hand
  if (!hand->is_object()) bad("hand: expected an object");
  const auto kind = hand->find("source");
  if (kind == hand->end() || !kind->is_string()) bad("hand.source: expected \"controller\" or \"hand\"");
  const std::string& source = kind->get_ref<const std::string&>();
  if (source == "controller") {
    in.source = XrSource::Controller;
    const auto ray = hand->find("ray");
    if (ray == hand->end()) bad("hand.ray: missing");
    in.ray = pose(*ray, "hand.ray");
    in.trigger = unitValue(*hand, "trigger", "hand");
    in.squeeze = unitValue(*hand, "squeeze", "hand");
  } else if (source == "hand") {
    in.source = XrSource::Hand;
    const auto tips = hand->find("tips");
    if (tips == hand->end() || !tips->is_array() || tips->size() != kFingerCount)
      bad("hand.tips: expected 5 entries, thumb to little");
    for (int f = 0; f < kFingerCount; ++f) {
      const json& t = (*tips)[std::size_t(f)];
      in.tips[f] = t.is_null() ? Vec3::Constant(std::numeric_limits<float>::quiet_NaN())
                               : vec3(t, fmt::format("hand.tips[{}]", f));
    }
  } else {
    bad(fmt::format("hand.source: unknown source '{}'", excerpt(source, 32)));
  }
  return in;
}

StudyReply studyReply(const json& m) {
  StudyReply r;
  const auto panel = m.find("panel");
  if (panel == m.end() || !panel->is_number_unsigned()) bad("panel: expected the panel's id");
  r.panel = panel->get<std::uint64_t>();
  const auto action = m.find("action");
  if (action == m.end() || !action->is_string()) bad("action: expected a string");
  const std::string& a = action->get_ref<const std::string&>();
  if (a == "start")
    r.action = StudyReply::Action::Start;
  else if (a == "continue")
    r.action = StudyReply::Action::Continue;
  else if (a == "submit")
    r.action = StudyReply::Action::Submit;
  else if (a == "retry")
    r.action = StudyReply::Action::Retry;
  else
    bad(fmt::format("action: unknown action '{}'", excerpt(a, 32)));
  const auto list = [&](const char* key) -> const json* {
    const auto it = m.find(key);
    if (it == m.end()) return nullptr;
    if (!it->is_array() || it->size() > kMaxStudyItems)
      bad(fmt::format("{}: expected an array of at most {}", key, kMaxStudyItems));
    return &*it;
  };
  if (const json* ratings = list("ratings"))
    for (const json& v : *ratings) {
      if (!v.is_number_integer() || std::abs(v.get<std::int64_t>()) > 100)
        bad("ratings: expected integers in -100..100");
      r.ratings.push_back(v.get<int>());
    }
  if (const json* texts = list("texts"))
    for (const json& v : *texts) {
      if (!v.is_string() || v.get_ref<const std::string&>().size() > kMaxStudyTextBytes)
        bad(fmt::format("texts: expected strings of at most {} bytes", kMaxStudyTextBytes));
      r.texts.push_back(v.get<std::string>());
    }
  return r;
}

}  // namespace

ClientMessage parseClientMessage(std::string_view text) {
  if (!jsonDepthWithin(text, kMaxJsonDepth)) bad(fmt::format("JSON nested deeper than {}", kMaxJsonDepth));
  json m = json::parse(text, nullptr, false);
  if (m.is_discarded()) bad("malformed JSON");
  if (!m.is_object()) bad("expected a JSON object");
  const auto type = m.find("type");
  if (type == m.end() || !type->is_string()) bad("missing \"type\"");
  const std::string& t = type->get_ref<const std::string&>();
  ClientMessage out;
  if (t == "input") {
    out.type = ClientMessage::Type::Input;
    out.input = input(m);
  } else if (t == "ping") {
    out.type = ClientMessage::Type::Ping;
    const auto at = m.find("t");
    if (at != m.end()) out.pingTime = number(*at, "t", 1e15f);
  } else if (t == "hello") {
    out.type = ClientMessage::Type::Hello;
    const auto client = m.find("client");
    if (client != m.end()) {
      if (!client->is_string()) bad("client: expected a string");
      out.client = std::string(excerpt(client->get_ref<const std::string&>(), 64));
    }
  } else if (t == "study") {
    out.type = ClientMessage::Type::Study;
    out.study = studyReply(m);
  } else {
    bad(fmt::format("unknown message type '{}'", excerpt(t, 32)));
  }
  return out;
}

// --- Server messages ------------------------------------------------------------------------------

std::vector<std::uint8_t> encodeTopology(std::span<const ViewMesh> meshes) {
  std::size_t size = kTopologyHeaderBytes + kTopologyBodyBytes * meshes.size();
  for (const ViewMesh& m : meshes) size += 12 * m.triangles.size();
  std::vector<std::uint8_t> out(size, 0);
  putCommon(out.data(), MessageKind::Topology);
  put(out.data() + 8, std::uint32_t(meshes.size()));
  std::uint8_t* body = out.data() + kTopologyHeaderBytes;
  std::uint8_t* tris = body + kTopologyBodyBytes * meshes.size();
  for (const ViewMesh& m : meshes) {
    put(body, std::uint32_t(m.vertexCount()));
    put(body + 4, std::uint32_t(m.triangles.size()));
    put(body + 8, std::uint32_t(m.kind == BodyKind::Cloth ? 1 : 0));
    body += kTopologyBodyBytes;
    for (const Triangle& t : m.triangles)
      for (int k = 0; k < 3; ++k, tris += 4) put(tris, std::uint32_t(t[k]));
  }
  return out;
}

std::array<std::uint8_t, frame::kHeaderBytes> encodeFrameHeader(const Snapshot& s, std::uint32_t number,
                                                                std::uint32_t flags) {
  std::array<std::uint8_t, frame::kHeaderBytes> h{};
  std::uint8_t* p = h.data();
  putCommon(p, MessageKind::Frame);
  put(p + frame::kNumber, number);
  put(p + frame::kStep, std::uint64_t(s.step));
  put(p + frame::kTime, s.time);
  for (int f = 0; f < kFingerCount; ++f) {
    const FingerHaptics& finger = s.haptics.fingers[f];
    put(p + frame::kForce + 4 * f, s.fingerPresent[f] ? clampUnit(finger.force) : 0.0f);
    put(p + frame::kNewtons + 4 * f, s.fingerPresent[f] ? clampNewtons(finger.newtons) : 0.0f);
    if (s.fingerPresent[f]) flags |= 1u << (kFingerFlagShift + f);
    for (int k = 0; k < 3; ++k) put(p + frame::kFingertips + 12 * f + 4 * k, s.fingertips[f][k]);
  }
  put(p + frame::kPaper, clampUnit(s.haptics.paper));
  if (s.grasping) flags |= kGrasping;
  if (s.contact) flags |= kContact;
  put(p + frame::kFlags, flags);
  put(p + frame::kRadius, s.fingertipRadius);
  put(p + frame::kStepWallMs, float(s.stepWallMs));
  return h;
}

void setBlockCount(std::span<std::uint8_t, frame::kHeaderBytes> header, std::uint32_t blocks) {
  put(header.data() + frame::kBlocks, blocks);
}

std::vector<std::uint8_t> encodeBodyBlock(std::uint32_t body, std::span<const Vec3> positions, QuantBox& box) {
  // Refit when a position is outside (or the box is new): bounds grown by half, at least 1 cm.
  bool inside = box.valid;
  Vec3 lo = Vec3::Constant(std::numeric_limits<float>::max()), hi = -lo;
  for (const Vec3& x : positions) {
    if (!x.allFinite()) continue;
    lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
    if (inside && ((x - box.origin).array() < 0.0f || (x - box.origin).array() > 65535.0f * box.scale.array()).any())
      inside = false;
  }
  if (!inside) {
    if (!(lo.array() <= hi.array()).all()) lo = hi = Vec3::Zero();  // nothing finite
    const Vec3 margin = (0.5f * (hi - lo)).cwiseMax(Vec3::Constant(0.01f));
    box.origin = lo - margin;
    box.scale = (hi - lo + 2.0f * margin) / 65535.0f;
    box.valid = true;
  }
  // The values last sent count only in the same box, for as many positions.
  const bool fresh = !inside || box.sent.size() != 3 * positions.size();
  if (fresh) box.sent.assign(3 * positions.size(), 0);
  const std::size_t data = 6 * positions.size();
  std::vector<std::uint8_t> out(frame::kBlockHeaderBytes + (data + 3) / 4 * 4, 0);
  std::uint8_t* p = out.data();
  put(p, body);
  put(p + 4, std::uint32_t(positions.size()));
  for (int k = 0; k < 3; ++k) {
    put(p + 8 + 4 * k, box.origin[k]);
    put(p + 20 + 4 * k, box.scale[k]);
  }
  p += frame::kBlockHeaderBytes;
  const Vec3 inv = box.scale.cwiseInverse();
  std::uint16_t* sent = box.sent.data();
  for (const Vec3& x : positions)
    for (int k = 0; k < 3; ++k, p += 2, ++sent) {
      const float q = std::isfinite(x[k]) ? std::round((x[k] - box.origin[k]) * inv[k]) : 0.0f;
      const auto value = std::uint16_t(std::clamp(q, 0.0f, 65535.0f));
      if (fresh || std::abs(int(value) - int(*sent)) > 1) *sent = value;
      put(p, *sent);
    }
  return out;
}

std::string sceneMessage(const BuiltScene& scene, std::span<const ViewMesh> meshes, double frameRate) {
  json bodies = json::array();
  for (const ViewMesh& m : meshes) {
    const SceneBody& b = scene.bodies.at(m.body);
    const Eigen::AlignedBox3f box = bodyBounds(*scene.world, b.id);
    bodies.push_back({{"name", m.name},
                      {"kind", m.kind == BodyKind::Cloth ? "cloth" : "soft"},
                      {"vertices", m.vertexCount()},
                      {"triangles", m.triangles.size()},
                      {"top", {b.top.x(), b.top.y(), b.top.z()}},
                      {"min", {box.min().x(), box.min().y(), box.min().z()}},
                      {"max", {box.max().x(), box.max().y(), box.max().z()}}});
  }
  json fingers = json::array();
  const HandRigSettings& hand = scene.session.hand;
  for (int f = 0; f < kFingerCount; ++f)
    if (scene.spec.hand.enabled && hand.fingers[f]) fingers.push_back(std::string(fingerName(Finger(f))));
  json actions = json::array();
  for (const HandAction& a : scene.actions)
    actions.push_back({{"kind", a.kind == ActionKind::Poke ? "poke" : "grasp"},
                       {"finger", std::string(fingerName(a.finger))},
                       {"target", {a.target.x(), a.target.y(), a.target.z()}}});
  const json m = {{"type", "scene"},
                  {"name", scene.spec.name},
                  {"description", scene.spec.description},
                  {"rate", 1.0 / scene.spec.solver.timeStep},
                  {"frameRate", frameRate},
                  {"bodies", bodies},
                  {"fingers", fingers},
                  {"fingertipRadius", scene.spec.hand.enabled ? hand.geometry.fingertipRadius : 0.0f},
                  {"actions", actions}};
  return m.dump();
}

}  // namespace vrd::vr
