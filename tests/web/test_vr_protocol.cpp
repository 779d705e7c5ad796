// The VR server's pieces without a network (web/): the wire format as docs/vr.md lays it out,
// the viewers' JSON messages and what is refused, the controller and hand mappings, and which
// request paths map to files.

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "test_support.h"
#include "vrdeform/web/static_files.h"
#include "vrdeform/web/vr_protocol.h"
#include "vrdeform/web/xr_hand.h"

namespace vrd {
namespace {

template <class T>
T read(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}

// Decodes a body block as a page does (docs/vr.md): origin + q * scale per axis.
std::vector<Vec3> decodeBlock(const std::vector<std::uint8_t>& block) {
  const std::uint32_t n = read<std::uint32_t>(block.data() + 4);
  Vec3 origin, scale;
  for (int k = 0; k < 3; ++k) {
    origin[k] = read<float>(block.data() + 8 + 4 * k);
    scale[k] = read<float>(block.data() + 20 + 4 * k);
  }
  std::vector<Vec3> out(n);
  for (std::uint32_t i = 0; i < n; ++i)
    for (int k = 0; k < 3; ++k)
      out[i][k] = origin[k] + float(read<std::uint16_t>(block.data() + 32 + 6 * i + 2 * k)) * scale[k];
  return out;
}

TEST(VrProtocol, BodyBlocksRoundTripWithinAQuantumAndStayIdenticalAtRest) {
  std::vector<Vec3> x;
  for (int i = 0; i < 101; ++i) x.emplace_back(0.001f * i, 0.05f + 0.0005f * i, -0.2f + 0.002f * i);
  vr::QuantBox box;
  const auto block = vr::encodeBodyBlock(7, x, box);
  EXPECT_EQ(read<std::uint32_t>(block.data()), 7u);
  EXPECT_EQ(block.size() % 4, 0u);
  EXPECT_EQ(block.size(), vr::frame::kBlockHeaderBytes + (6 * 101 + 3) / 4 * 4);
  const std::vector<Vec3> y = decodeBlock(block);
  for (std::size_t i = 0; i < x.size(); ++i)
    EXPECT_LE((y[i] - x[i]).cwiseAbs().maxCoeff(), 0.5f * box.scale.maxCoeff() + 1e-7f) << i;
  // Bounds 0.2 m wide grown by half on each side: a quantum of 0.4 m / 65535, about 6 um.
  EXPECT_LT(box.scale.maxCoeff(), 1e-5f);

  // The same positions give the same bytes (so a body at rest is left out of frames), and so do
  // positions jittered by less than a quantum, as float rounding jitters a body at rest; a move
  // inside the box keeps the box; one outside refits it.
  EXPECT_EQ(vr::encodeBodyBlock(7, x, box), block);
  std::vector<Vec3> jittered = x;
  for (std::size_t i = 0; i < x.size(); ++i) jittered[i] += (i % 2 ? 0.6f : -0.6f) * box.scale;
  EXPECT_EQ(vr::encodeBodyBlock(7, jittered, box), block);
  const vr::QuantBox before = box;
  x[3].y() += 0.01f;
  const std::vector<Vec3> z = decodeBlock(vr::encodeBodyBlock(7, x, box));
  EXPECT_EQ(box.origin, before.origin);
  EXPECT_NEAR(z[3].y(), x[3].y(), 0.5f * box.scale.y() + 1e-7f);  // a real move is sent
  for (std::size_t i = 0; i < x.size(); ++i)
    EXPECT_LE((z[i] - x[i]).cwiseAbs().maxCoeff(), 1.5f * box.scale.maxCoeff() + 1e-7f) << i;
  x[3].y() += 1.0f;
  const auto moved = vr::encodeBodyBlock(7, x, box);
  EXPECT_NE(box.origin, before.origin);
  EXPECT_NEAR(decodeBlock(moved)[3].y(), x[3].y(), box.scale.y());

  // NaN quantises to the origin instead of poisoning the frame.
  x[5] = Vec3::Constant(std::numeric_limits<float>::quiet_NaN());
  EXPECT_TRUE(decodeBlock(vr::encodeBodyBlock(7, x, box))[5].allFinite());
}

TEST(VrProtocol, FrameHeaderAtTheDocumentedOffsets) {
  Snapshot s;
  s.step = 12345678901ull;
  s.time = 2.5;
  s.fingerPresent = {true, true, false, false, false};
  s.haptics.fingers[1].force = 0.25f;
  s.haptics.fingers[1].newtons = 1.5f;
  s.haptics.fingers[2].force = 0.9f;  // an absent finger reads 0
  s.haptics.paper = std::numeric_limits<float>::quiet_NaN();
  s.fingertips[1] = Vec3(0.1f, 0.2f, 0.3f);
  s.fingertipRadius = 0.009f;
  s.grasping = true;
  auto h = vr::encodeFrameHeader(s, 42, vr::kDriven);
  vr::setBlockCount(h, 3);
  const std::uint8_t* p = h.data();
  EXPECT_EQ(std::memcmp(p, "VRD1", 4), 0);
  EXPECT_EQ(read<std::uint16_t>(p + 4), 2);
  EXPECT_EQ(read<std::uint32_t>(p + vr::frame::kNumber), 42u);
  EXPECT_EQ(read<std::uint32_t>(p + vr::frame::kBlocks), 3u);
  EXPECT_EQ(read<std::uint64_t>(p + vr::frame::kStep), 12345678901ull);
  EXPECT_EQ(read<double>(p + vr::frame::kTime), 2.5);
  EXPECT_EQ(read<float>(p + vr::frame::kForce + 4), 0.25f);
  EXPECT_EQ(read<float>(p + vr::frame::kForce + 8), 0.0f);
  EXPECT_EQ(read<float>(p + vr::frame::kNewtons + 4), 1.5f);
  EXPECT_EQ(read<float>(p + vr::frame::kPaper), 0.0f);
  const std::uint32_t flags = read<std::uint32_t>(p + vr::frame::kFlags);
  EXPECT_EQ(flags, vr::kGrasping | vr::kDriven | (3u << vr::kFingerFlagShift));
  EXPECT_EQ(read<float>(p + vr::frame::kRadius), 0.009f);
  EXPECT_EQ(read<float>(p + vr::frame::kFingertips + 12 + 8), 0.3f);
}

TEST(VrProtocol, InputMessages) {
  const auto m = vr::parseClientMessage(
      R"({"type":"input","head":{"p":[0,1.6,0],"q":[0,0,0,1]},
          "hand":{"source":"controller","ray":{"p":[0.1,0.2,0.3],"q":[0,0.7071068,0,0.7071068]},"trigger":0.5,"squeeze":1}})");
  ASSERT_EQ(m.type, vr::ClientMessage::Type::Input);
  EXPECT_EQ(m.input.source, XrSource::Controller);
  EXPECT_NEAR(m.input.ray.position.z(), 0.3f, 1e-7f);
  EXPECT_NEAR(m.input.ray.orientation.y(), 0.7071068f, 1e-6f);
  EXPECT_EQ(m.input.trigger, 0.5f);
  EXPECT_EQ(m.input.squeeze, 1.0f);
  ASSERT_TRUE(m.input.head);
  EXPECT_EQ(m.input.head->position.y(), 1.6f);

  const auto h = vr::parseClientMessage(
      R"({"type":"input","hand":{"source":"hand","tips":[[0,0.1,0],[0.01,0.1,0],null,[0.03,0.1,0],[0.04,0.1,0]]}})");
  EXPECT_EQ(h.input.source, XrSource::Hand);
  EXPECT_EQ(h.input.tips[1], Vec3(0.01f, 0.1f, 0.0f));
  EXPECT_TRUE(std::isnan(h.input.tips[2].x()));
  EXPECT_FALSE(h.input.head);

  EXPECT_EQ(vr::parseClientMessage(R"({"type":"input","head":null,"hand":null})").input.source, XrSource::None);
  EXPECT_EQ(vr::parseClientMessage(R"({"type":"ping","t":123.5})").pingTime, 123.5);
  EXPECT_EQ(vr::parseClientMessage(R"({"type":"hello","client":"page"})").client, "page");
}

TEST(VrProtocol, StudyReplies) {
  const auto m = vr::parseClientMessage(
      R"({"type":"study","panel":12,"action":"submit","ratings":[7,-3,1],"texts":["fine","a, \"quoted\"\nline"]})");
  ASSERT_EQ(m.type, vr::ClientMessage::Type::Study);
  EXPECT_EQ(m.study.panel, 12u);
  EXPECT_EQ(m.study.action, vr::StudyReply::Action::Submit);
  EXPECT_EQ(m.study.ratings, (std::vector<int>{7, -3, 1}));
  EXPECT_EQ(m.study.texts, (std::vector<std::string>{"fine", "a, \"quoted\"\nline"}));
  const auto start = vr::parseClientMessage(R"({"type":"study","panel":1,"action":"start"})");
  EXPECT_EQ(start.study.action, vr::StudyReply::Action::Start);
  EXPECT_TRUE(start.study.ratings.empty());
  EXPECT_EQ(vr::parseClientMessage(R"({"type":"study","panel":2,"action":"continue"})").study.action,
            vr::StudyReply::Action::Continue);
  EXPECT_EQ(vr::parseClientMessage(R"({"type":"study","panel":2,"action":"retry"})").study.action,
            vr::StudyReply::Action::Retry);

  using testing::errorOf;
  const auto reason = [](const std::string& text) { return errorOf([&] { vr::parseClientMessage(text); }); };
  EXPECT_EQ(reason(R"({"type":"study","action":"start"})"), "panel: expected the panel's id");
  EXPECT_EQ(reason(R"({"type":"study","panel":-1,"action":"start"})"), "panel: expected the panel's id");
  EXPECT_EQ(reason(R"({"type":"study","panel":1})"), "action: expected a string");
  EXPECT_EQ(reason(R"({"type":"study","panel":1,"action":"skip"})"), "action: unknown action 'skip'");
  EXPECT_EQ(reason(R"({"type":"study","panel":1,"action":"submit","ratings":[1.5]})"),
            "ratings: expected integers in -100..100");
  EXPECT_EQ(reason(R"({"type":"study","panel":1,"action":"submit","ratings":[1000]})"),
            "ratings: expected integers in -100..100");
  EXPECT_EQ(reason(R"({"type":"study","panel":1,"action":"submit","ratings":{}})"),
            "ratings: expected an array of at most 256");
  EXPECT_EQ(reason(R"({"type":"study","panel":1,"action":"submit","texts":[3]})"),
            "texts: expected strings of at most 4000 bytes");
  EXPECT_EQ(reason(R"({"type":"study","panel":1,"action":"submit","texts":[")" + std::string(4001, 'x') + R"("]})"),
            "texts: expected strings of at most 4000 bytes");
}

TEST(VrProtocol, RefusesBadMessagesWithAReason) {
  using testing::errorOf;
  const auto reason = [](const std::string& text) { return errorOf([&] { vr::parseClientMessage(text); }); };
  EXPECT_EQ(reason("{"), "malformed JSON");
  EXPECT_EQ(reason(""), "malformed JSON");
  EXPECT_EQ(reason("[1,2]"), "expected a JSON object");
  EXPECT_EQ(reason(R"({"t":1})"), "missing \"type\"");
  EXPECT_EQ(reason(R"({"type":7})"), "missing \"type\"");
  EXPECT_EQ(reason(R"({"type":"launch"})"), "unknown message type 'launch'");
  EXPECT_EQ(reason(std::string(100, '[') + std::string(100, ']')), "JSON nested deeper than 8");
  EXPECT_NE(reason(R"({"type":"input","hand":{"source":"controller","ray":{"p":[0,0,1e999],"q":[0,0,0,1]}}})"), "");
  EXPECT_EQ(reason(R"({"type":"input","hand":{"source":"controller","ray":{"p":[0,0,"x"],"q":[0,0,0,1]}}})"),
            "hand.ray.p[2]: expected a number");
  EXPECT_EQ(reason(R"({"type":"input","hand":{"source":"controller","ray":{"p":[0,0,5000],"q":[0,0,0,1]}}})"),
            "hand.ray.p[2]: 5000 is out of range");
  EXPECT_EQ(reason(R"({"type":"input","hand":{"source":"controller","ray":{"p":[0,0,0],"q":[0,0,0,0.002]}}})"),
            "hand.ray.q: not a unit quaternion (norm 0.002)");
  EXPECT_EQ(reason(R"({"type":"input","hand":{"source":"controller","ray":{"p":[0,0,0]}}})"),
            "hand.ray: needs \"p\" and \"q\"");
  EXPECT_EQ(reason(R"({"type":"input","hand":{"source":"controller","ray":{"p":[0,0,0],"q":[0,0,0,1]},"trigger":2}})"),
            "hand.trigger: 2 is out of range");
  EXPECT_EQ(reason(R"({"type":"input","hand":{"source":"hand","tips":[[0,0,0]]}})"),
            "hand.tips: expected 5 entries, thumb to little");
  EXPECT_EQ(reason(R"({"type":"input","hand":{"source":"glove"}})"), "hand.source: unknown source 'glove'");
  EXPECT_EQ(reason(R"({"type":"hello","client":{}})"), "client: expected a string");
  // Strings with brackets do not count as nesting.
  EXPECT_EQ(vr::parseClientMessage(R"({"type":"hello","client":"[[[[[[[[[[[[\"]]"})").client, "[[[[[[[[[[[[\"]]");
}

TEST(XrHand, ControllerPinchClosesWithTheTrigger) {
  XrHandSettings s;
  const float r = 0.009f;
  XrInput in;
  in.source = XrSource::Controller;
  in.ray.position = Vec3(0.1f, 0.3f, -0.2f);
  in.ray.orientation = Eigen::Quaternionf(0.5f, -0.5f, -0.5f, -0.5f);  // pointing down, up along +x
  const HandFrame open = xrHandFrame(in, s, r);
  ASSERT_TRUE(open.direct);
  const Vec3 middle = in.ray.position - Vec3(0, s.reach, 0);
  const Vec3 thumb = open.fingertips[int(Finger::Thumb)], index = open.fingertips[int(Finger::Index)];
  EXPECT_LT((0.5f * (thumb + index) - middle).norm(), 1e-6f);
  EXPECT_NEAR(index.x() - thumb.x(), s.openGap + 2 * r, 1e-6f);  // index on +x: the gap between surfaces
  // The middle trails the index back up along the ray.
  EXPECT_NEAR(open.fingertips[int(Finger::Middle)].y() - index.y(), 2.2f * r, 1e-6f);

  in.trigger = 1.0f;
  const HandFrame closed = xrHandFrame(in, s, r);
  EXPECT_NEAR((closed.fingertips[int(Finger::Index)] - closed.fingertips[int(Finger::Thumb)]).norm(),
              s.closedGap + 2 * r, 1e-6f);
  // A glove's closure replaces the trigger.
  const HandFrame glove = xrHandFrame(in, s, r, 0.0f);
  EXPECT_NEAR((glove.fingertips[1] - glove.fingertips[0]).norm(), s.openGap + 2 * r, 1e-6f);
}

TEST(XrHand, TrackedTipsPassThroughAndNothingTrackedIsParked) {
  XrHandSettings s;
  s.park = Vec3(0.0f, 0.4f, 0.0f);
  XrInput in;
  in.source = XrSource::Hand;
  for (int f = 0; f < kFingerCount; ++f) in.tips[f] = Vec3(0.01f * f, 0.1f, 0.0f);
  in.tips[4] = Vec3::Constant(std::numeric_limits<float>::quiet_NaN());
  const HandFrame h = xrHandFrame(in, s, 0.009f);
  EXPECT_TRUE(h.direct);
  EXPECT_EQ(h.fingertips[2], Vec3(0.02f, 0.1f, 0.0f));
  EXPECT_TRUE(std::isnan(h.fingertips[4].x()));  // HandRig keeps that fingertip where it was

  in.source = XrSource::None;
  const HandFrame parked = xrHandFrame(in, s, 0.009f);
  EXPECT_LT((0.5f * (parked.fingertips[0] + parked.fingertips[1]) - s.park).norm(), 1e-6f);
}

TEST(StaticFiles, MapsPathsIntoTheWebFolderOnly) {
  namespace fs = std::filesystem;
  const fs::path web = fs::temp_directory_path() / "vrdeform_static_files_test";
  fs::remove_all(web);
  fs::create_directories(web / "public" / "sub");
  fs::create_directories(web / "node_modules" / "three" / "build");
  fs::create_directories(web / "node_modules" / "three" / "src");
  for (const fs::path& p :
       {web / "public" / "index.html", web / "public" / "a b.js", web / "public" / "sub" / "index.html",
        web / "node_modules" / "three" / "build" / "three.module.js", web / "node_modules" / "three" / "src" / "x.js",
        web / "secret.txt"})
    std::ofstream(p) << "x";
  fs::create_symlink(web / "secret.txt", web / "public" / "link.txt");

  const auto at = [&](std::string_view target) { return resolveStaticPath(web, target); };
  EXPECT_EQ(at("/"), fs::canonical(web / "public" / "index.html"));
  EXPECT_EQ(at("/?v=1"), fs::canonical(web / "public" / "index.html"));
  EXPECT_EQ(at("/sub/"), fs::canonical(web / "public" / "sub" / "index.html"));
  EXPECT_EQ(at("/a%20b.js"), fs::canonical(web / "public" / "a b.js"));
  EXPECT_EQ(at("/three/build/three.module.js"),
            fs::canonical(web / "node_modules" / "three" / "build" / "three.module.js"));
  EXPECT_TRUE(hasThreeJs(web));
  for (const char* bad :
       {"/../secret.txt", "/sub/../../secret.txt", "/%2e%2e/secret.txt", "/..%2fsecret.txt",
        "/sub%2f..%2f..%2fsecret.txt", "/link.txt", "/three/src/x.js", "/three/build/../../../secret.txt", "/x%00.html",
        "/%zz", "/%2", "/sub\\..\\..\\secret.txt", "//etc/passwd", "/sub", "relative", "", "/nothing.js",
        "/three/examples/jsm/../../build/three.module.js"})
    EXPECT_FALSE(at(bad)) << bad;
  EXPECT_EQ(mimeType("a/b.js"), "text/javascript; charset=utf-8");
  EXPECT_EQ(mimeType("index.html"), "text/html; charset=utf-8");
  EXPECT_EQ(mimeType("x.bin"), "application/octet-stream");
  fs::remove_all(web);
}

}  // namespace
}  // namespace vrd
