// What a scene file must be before it is parsed (src/scene/json_guard.cpp): bounded (a pipe or a
// device that never ends is refused, not read forever), nested at most 64 deep, free of duplicate
// keys (two materials of one name, two radii in one sphere); and every number must fit the
// floats the device stores.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>

#include "core/file_io.hpp"
#include "lucent/error.hpp"
#include "lucent/scene.hpp"
#include "scene/validate.hpp"
#include "support.hpp"

namespace test_scene_guard {

namespace {

using lucent::test::CommandResult;
using lucent::test::run_cli;

std::string q(const std::string& s) { return "'" + s + "'"; }

/// Runs `feed | lucent ARGS` (run_cli reads standard input from /dev/null).
CommandResult piped(const std::string& feed, const std::string& args) {
  std::string dir = lucent::test::temp_dir();
  std::string cmd = feed + " | '" + LUCENT_CLI_PATH + "' " + args + " >" + q(dir + "/out") + " 2>" +
                    q(dir + "/err");
  CommandResult r;
  r.status = std::system(cmd.c_str());
  r.err = lucent::test::read_file(dir + "/err");
  return r;
}

/// The message of the error parsing `json` (as <dir>/scene.json), or "" when it parses.
std::string parse_error(const std::string& json) {
  try {
    lucent::test::scene_from(json);
  } catch (const lucent::Error& e) {
    return e.what();
  }
  return "";
}

std::string after_path(const std::string& msg) {
  auto at = msg.find("scene.json");
  return at == std::string::npos ? msg : msg.substr(at + 10);
}

TEST(SceneGuard, DeepNestingIsRefusedQuickly) {
  // 10^5 levels crashed the loader (stack overflow in recursive code)
  for (const char* open : {"[", "{\"a\":"}) {
    std::string json = "{\"camera\": ";
    for (int i = 0; i < 100000; ++i) json += open;
    auto t0 = std::chrono::steady_clock::now();
    std::string msg = parse_error(json);
    double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_LT(s, 2.0);
    EXPECT_NE(msg.find("nested deeper than 64 levels"), std::string::npos) << msg.substr(0, 300);
    EXPECT_NE(msg.find("scene.json:1:"), std::string::npos) << msg.substr(0, 300);
    // the depth the message says a scene needs: a matrix row is 7 containers deep (it said 6)
    EXPECT_NE(msg.find("(a scene needs 7: "), std::string::npos) << msg.substr(0, 300);
  }
  EXPECT_EQ(parse_error(R"({"materials": {"m": {"type": "diffuse"}}, "shapes": [{"type":
      "triangles", "material": "m", "positions": [[0,0,0],[1,0,0],[0,1,0]], "indices": [0,1,2],
      "transform": [{"matrix": [[1,0,0,0],[0,1,0,0],[0,0,1,0],[0,0,0,1]]}]}]})"),
            "");
  // 63 levels of arrays are only a schema error
  std::string ok = "{\"camera\": {\"position\": ";
  for (int i = 0; i < 61; ++i) ok += "[";
  for (int i = 0; i < 61; ++i) ok += "]";
  EXPECT_EQ(parse_error(ok + "}}").find("nested"), std::string::npos);
}

TEST(SceneGuard, DuplicateKeysNameBothPlaces) {
  EXPECT_EQ(after_path(parse_error(R"({"materials": {
  "white": {"type": "diffuse"},
  "white": {"type": "mirror"}}})")),
            ":3:3: /materials/white: duplicate material name 'white' (first at 2:3)");
  EXPECT_EQ(after_path(parse_error(R"({"film": {"width": 8, "width": 9}})")),
            ":1:23: /film/width: duplicate key (first at 1:11)");
  EXPECT_EQ(
      after_path(parse_error(
          R"({"shapes": [{"type": "sphere"}, {"type": "sphere", "radius": 1, "radius": 2}]})")),
      ":1:65: /shapes/1/radius: duplicate key (first at 1:52)");
  // escaped quotes inside a key do not confuse the place
  EXPECT_EQ(after_path(parse_error(R"({"a\"b": 1, "a\"b": 2})")),
            ":1:13: /a\"b: duplicate key (first at 1:2)");
  // a JSON pointer (RFC 6901): '~' in a key is "~0", '/' is "~1"
  EXPECT_EQ(after_path(parse_error(R"({"materials": {"a/b~": {}, "a/b~": {}}})")),
            ":1:28: /materials/a~1b~0: duplicate material name 'a/b~' (first at 1:16)");
  // the same key in two different objects is fine
  EXPECT_EQ(parse_error(R"({"film": {"width": 8}, "camera": {"fov": 30}})"), "");
}

TEST(SceneGuard, NumbersBeyondFloatRangeNameTheirPointer) {
  // finite in JSON (a double), infinite in the device's floats: the camera basis became inf/NaN
  EXPECT_EQ(after_path(parse_error(R"({"camera": {"position": [1e39, 0, 0]}})")),
            ": /camera/position/0: must fit in a float (magnitude at most 3.4e38), got 1e+39");
  EXPECT_EQ(after_path(parse_error(R"({"camera": {"fov": -4e38}})")),
            ": /camera/fov: must fit in a float (magnitude at most 3.4e38), got -4e+38");
  EXPECT_EQ(
      after_path(parse_error(R"({"materials": {"m": {"type": "diffuse",
    "emission": [1, 1e300, 1]}}})")),
      ": /materials/m/emission/1: must fit in a float (magnitude at most 3.4e38), got 1e+300");
  EXPECT_EQ(parse_error(R"({"materials": {"m": {"type": "diffuse", "emission": [3.4e38, 0, 0]}}})"),
            "");
  // inline triangles that a transform takes beyond float range
  EXPECT_EQ(after_path(parse_error(R"({"materials": {"m": {"type": "diffuse"}},
    "shapes": [{"type": "triangles", "positions": [[1, 0, 0], [0, 0, 0], [0, 1, 0]],
                "indices": [0, 1, 2], "material": "m",
                "transform": [{"scale": 1e30}, {"scale": 1e30}]}]})")),
            ": /shapes/0/positions/0: its largest coordinate after the transform, "
            "1.0000000000000001e+60, is "
            "beyond lucent's geometry range (coordinates of magnitude at most 1e+12, where the "
            "kernel's float intersection arithmetic still holds)");
}

// Geometry beyond limits::kMaxCoordinate (1e12) is an error naming its place: the kernel's float
// triangle test overflows near 7e12 and a sphere's squared radius at 1.8e19, and such shapes
// vanished from the image (a floor sphere of radius 1e20), or an emitter's area became infinite
// and every light's selection probability NaN (a lamp of radius 1e19), without a word.
TEST(SceneGuard, GeometryBeyondRangeNamesItsPlace) {
  const std::string range =
      " is beyond lucent's geometry range (coordinates of magnitude at most 1e+12, where the "
      "kernel's float intersection arithmetic still holds)";
  const std::string m = R"("materials": {"m": {"type": "diffuse"}}, )";
  EXPECT_EQ(after_path(parse_error("{" + m + R"("shapes": [{"type": "sphere",
    "center": [0, -1e20, 0], "radius": 1e20, "material": "m"}]})")),
            ": /shapes/0/center/1: -1e+20" + range);
  EXPECT_EQ(after_path(parse_error("{" + m + R"("shapes": [{"type": "sphere",
    "center": [0, -1e12, 0], "radius": 1e6, "material": "m"}]})")),
            // (the value itself: "1e+12 is beyond ... at most 1e+12" contradicted itself)
            ": /shapes/0/radius: the sphere's farthest coordinate, 1.000001e+12," + range);
  EXPECT_EQ(after_path(parse_error("{" + m + R"("shapes": [{"type": "sphere",
    "center": [0, 0, 0], "radius": 1e19, "material": "m"}]})")),
            ": /shapes/0/radius: the sphere's farthest coordinate, 1e+19," + range);
  EXPECT_EQ(after_path(parse_error("{" + m + R"("shapes": [{"type": "triangles",
    "positions": [[-2e12, 0, 0], [0, 0, 0], [0, 1, 0]], "indices": [0, 1, 2], "material": "m"}]})")),
            ": /shapes/0/positions/0: its largest coordinate, 2e+12," + range);
  EXPECT_EQ(after_path(parse_error(R"({"camera": {"position": [0, 5e12, 0]}})")),
            ": /camera/position/1: 5e+12" + range);
  EXPECT_EQ(
      after_path(parse_error(
          R"({"lights": [{"type": "point", "position": [0, 0, 3e15], "intensity": [1, 1, 1]}]})")),
      ": /lights/0/position/2: 3e+15" + range);
  // at the edge of the range: accepted
  EXPECT_EQ(parse_error("{" + m + R"("shapes": [{"type": "sphere",
    "center": [0, -5e11, 0], "radius": 5e11, "material": "m"}]})"),
            "");
  // built through the API, without SceneBuilder: validate_scene, run by every render
  lucent::Scene s = lucent::test::scene_from("{" + m + R"("shapes": [{"type": "sphere",
    "center": [0, 0, 0], "radius": 1, "material": "m"}, {"type": "triangles",
    "positions": [[1, 0, 0], [0, 0, 0], [0, 1, 0]], "indices": [0, 1, 2], "material": "m"}]})");
  lucent::Scene far_sphere = s, far_vertex = s;
  far_sphere.spheres[0].radius = 1e20;
  far_vertex.positions[1].z = -8e12;
  auto validate_error = [](const lucent::Scene& scene) {
    return after_path(lucent::test::error_of([&] { lucent::scene_detail::validate_scene(scene); }));
  };
  EXPECT_EQ(validate_error(s), "");
  EXPECT_EQ(validate_error(far_sphere),
            ": /shapes/0/radius: the sphere's farthest coordinate, 1e+20," + range);
  EXPECT_EQ(validate_error(far_vertex), ": /shapes/1 (triangle 0)/v/1/2: -8e+12" + range);
}

TEST(SceneGuard, StreamsAndDevicesAreBounded) {
  std::string dir = lucent::test::temp_dir();
  std::string out = dir + "/o.png";
  // a device: refused without reading
  auto r = run_cli("render /dev/zero -o " + q(out));
  EXPECT_EQ(
      r.err,
      "lucent: error: /dev/zero: is a device, not a scene file (only regular files are read)\n");
  // an endless pipe of NUL bytes: stopped at the first one
  r = piped("head -c 100000000 /dev/zero", "render /dev/stdin -o " + q(out));
  EXPECT_EQ(r.err, "lucent: error: /dev/stdin: byte 1 is a NUL byte: not a text scene file\n");
  // an endless pipe of text: stopped at the limit (256 MiB)
  auto t0 = std::chrono::steady_clock::now();
  r = piped("yes", "render /dev/stdin -o " + q(out));
  double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_EQ(r.err,
            "lucent: error: /dev/stdin: more than the 256.0 MiB a scene file may have (a "
            "stream that never ends?)\n");
  EXPECT_LT(s, 20);
  // a pipe that ends is a scene like any other
  std::string scene = dir + "/s.json";
  lucent::test::write_file(
      scene, R"({"film": {"width": 4, "height": 4}, "integrator": {"type": "albedo", "spp": 1}})");
  // (the full kernel, which many tests share: a specialised one cost CI a cold kernel build)
  r = piped("cat " + q(scene), "render /dev/stdin -o " + q(out) + " --quiet --no-specialize");
  EXPECT_EQ(r.status, 0) << r.err;
  // a FIFO nobody writes to: read as empty at once, not waited for
  std::string fifo = dir + "/fifo.json";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  r = run_cli("render " + q(fifo) + " -o " + q(out));
  EXPECT_NE(r.err.find(fifo + ":1:1: invalid JSON"), std::string::npos) << r.err;
}

// A piped scene has no directory of its own: its relative file names are taken from the current
// directory, as a shell's would be (they were looked for in /dev), and /dev/stdin redirected from
// a file is that file, in its directory.
TEST(SceneGuard, PipedSceneFindsItsFilesFromTheCurrentDirectory) {
  std::string dir = lucent::test::temp_dir();
  std::filesystem::create_directories(dir + "/sub");
  lucent::test::write_file(dir + "/sub/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  lucent::test::write_file(dir + "/sub/s.json",
                           R"({"film": {"width": 4, "height": 4},
    "integrator": {"type": "albedo", "spp": 1},
    "shapes": [{"type": "mesh", "file": "tri.obj"}]})");
  const std::string out = q(dir + "/o.pfm") + " --quiet";
  CommandResult r =
      piped("cd " + q(dir + "/sub") + " && cat s.json", "render /dev/stdin -o " + out);
  EXPECT_EQ(r.status, 0) << r.err;
  r = piped("cd " + q(dir) + " && true", "render /dev/stdin -o " + out + " < sub/s.json");
  EXPECT_EQ(r.status, 0) << r.err;
  r = piped("cd " + q(dir) + " && cat sub/s.json", "render /dev/stdin -o " + out);
  EXPECT_EQ(r.err,
            "lucent: error: /dev/stdin: /shapes/0/file: tri.obj: cannot open OBJ file (No such "
            "file or directory)\n");
}

// A scene reached through a linked directory: "../x" in it is where the system finds it, beside
// the directory the link points to (a lexical "link/.." made it beside the link: the scene opened,
// its mesh did not). Found by loading scenes/textured.json through a link to scenes/.
TEST(SceneGuard, DotDotAfterALinkedDirectoryIsTheLinkTargetsParent) {
  namespace fs = std::filesystem;
  std::string dir = lucent::test::temp_dir();
  fs::create_directories(dir + "/project/scenes");
  fs::create_directories(dir + "/elsewhere/deep");
  lucent::test::write_file(dir + "/project/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  lucent::test::write_file(dir + "/project/scenes/s.json",
                           R"({"film": {"width": 4, "height": 4},
    "integrator": {"type": "albedo", "spp": 1},
    "shapes": [{"type": "mesh", "file": "../tri.obj"}]})");
  fs::create_directory_symlink(dir + "/project/scenes", dir + "/elsewhere/deep/sc");
  const std::string via_link = dir + "/elsewhere/deep/sc/s.json";
  lucent::Scene scene;
  ASSERT_NO_THROW(scene = lucent::load_scene(via_link));
  ASSERT_EQ(scene.shapes.size(), 1u);
  EXPECT_TRUE(fs::equivalent(scene.shapes[0].file, dir + "/project/tri.obj"))
      << scene.shapes[0].file;
  // without links the name stays as short as before
  scene = lucent::load_scene(dir + "/project/scenes/./s.json");
  EXPECT_EQ(scene.shapes[0].file, dir + "/project/tri.obj");
}

// A writer that holds a pipe open and sends nothing: the read gives up after the idle time.
TEST(SceneGuard, SilentPipeTimesOut) {
  std::string fifo = lucent::test::temp_dir() + "/silent";
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  int keep = ::open(fifo.c_str(), O_RDWR | O_NONBLOCK);  // a writer that never writes
  ASSERT_GE(keep, 0);
  lucent::io::ReadSpec spec;
  spec.what = "scene file";
  spec.allow_pipe = true;
  spec.stream_idle_seconds = 1;
  auto t0 = std::chrono::steady_clock::now();
  try {
    lucent::io::read_file(fifo, spec);
    ADD_FAILURE() << "no error";
  } catch (const lucent::Error& e) {
    EXPECT_EQ(std::string(e.what()),
              fifo + ": no data for 1 s after 0 bytes (a pipe that never ends?)");
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 5);
  ::close(keep);
  // and referenced files must be regular files
  spec.allow_pipe = false;
  spec.what = "texture";
  try {
    lucent::io::read_file(fifo, spec);
    ADD_FAILURE() << "no error";
  } catch (const lucent::Error& e) {
    EXPECT_EQ(std::string(e.what()),
              fifo + ": is a pipe, not a texture (only regular files are read)");
  }
}

}  // namespace

// validate_scene (run by every render) holds the loader's one-environment rule for scenes whose
// lights were set directly: two were accepted, the last became the escape light and the first was
// seen through light sampling only.
TEST(SceneGuard, OneEnvironmentAlsoForScenesBuiltDirectly) {
  lucent::Scene s =
      lucent::test::scene_from(R"({"lights": [{"type": "environment", "radiance": [1, 1, 1]}]})");
  lucent::scene_detail::validate_scene(s);
  s.lights.push_back(s.lights[0]);
  EXPECT_EQ(after_path(lucent::test::error_of([&] { lucent::scene_detail::validate_scene(s); })),
            ": /lights/1: only one environment light is allowed");
}

namespace {
// A value just past its limit is shown as given: an ior of 20.0000001 was "must be in [0.05, 20],
// got 20" (six significant digits), which named no mistake.
TEST(SceneGuard, AValueJustPastItsLimitIsShownAsGiven) {
  EXPECT_NE(parse_error(R"({"materials": {"m": {"type": "dielectric", "ior": 20.0000001}}})")
                .find("/materials/m/ior: must be in [0.05, 20], got 20.0000001"),
            std::string::npos);
  EXPECT_NE(parse_error(R"({"camera": {"fov": 180.0000001}})")
                .find("/camera/fov: must be in (0, 180) degrees, got 180.0000001"),
            std::string::npos);
}
}  // namespace

}  // namespace test_scene_guard
