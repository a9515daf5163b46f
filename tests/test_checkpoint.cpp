// Checkpoints (`lucent render --checkpoint FILE`, docs/parts.md, "Checkpoints"): a render killed
// with SIGKILL after a checkpoint, then run again, writes the image of the render that was never
// stopped; the checkpoint in between is a part file of exactly the samples [0, K) it claims; a
// checkpoint of another image is refused with one line, and so are the renders it cannot hold.
//
// Equality: the resumed image adds the checkpoint's sums and the second run's, where the single
// render added its passes in one sequence; the sample indices are the same, so the images agree
// to the rounding of those sums (double on a device with fp64, float pass sums without: within
// 1e-5 relative), while a checkpoint off by one sample differs by the noise (~10%, as
// Parts.CommandLinePartsMergeIntoTheSingleRender measures).
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "core/file_io.hpp"
#include "image/image_probe.hpp"
#include "lucent/compare.hpp"
#include "lucent/image.hpp"
#include "lucent/parts.hpp"
#include "support.hpp"

namespace test_checkpoint {

namespace {

namespace fs = std::filesystem;
using lucent::test::CommandResult;
using lucent::test::run_cli;

std::string q(const std::string& s) { return "'" + s + "'"; }

/// A diffuse sphere and a plane under a point light and a sky: every pixel noisy, 12x10.
std::string noisy_scene(const std::string& dir, const std::string& name = "scene.json",
                        double radius = 0.5) {
  std::string path = dir + "/" + name;
  lucent::test::write_file(path, R"({
    "camera": {"position": [0, 0, 5], "look_at": [0, 0, 0], "fov": 30},
    "film": {"width": 12, "height": 10},
    "integrator": {"type": "path", "spp": 8, "seed": 3},
    "materials": {"m": {"type": "diffuse", "albedo": [0.25, 0.5, 0.75]}},
    "shapes": [{"type": "triangles", "material": "m",
                "positions": [[-10,-10,0],[10,-10,0],[10,10,0],[-10,10,0]], "indices": [0,1,2, 0,2,3]},
               {"type": "sphere", "center": [0.3, 0.2, 0.5], "radius": )" +
                                     std::to_string(radius) + R"(, "material": "m"}],
    "lights": [{"type": "point", "position": [0.7, 0.4, 2.0], "intensity": [20, 20, 20]},
               {"type": "environment", "radiance": [0.3, 0.3, 0.3]}]
  })");
  return path;
}

/// Largest relative difference between two renders' pixel means; their sample counts must be
/// equal.
double max_relative_difference(const lucent::RenderResult& a, const lucent::RenderResult& b) {
  EXPECT_EQ(a.samples, b.samples);
  EXPECT_EQ(a.mean.rgb.size(), b.mean.rgb.size());
  double worst = 0;
  for (size_t i = 0; i < a.mean.rgb.size() && i < b.mean.rgb.size(); ++i) {
    const double x = a.mean.rgb[i], y = b.mean.rgb[i];
    const double scale = std::max(std::abs(x), std::abs(y));
    if (scale > 0) worst = std::max(worst, std::abs(x - y) / scale);
  }
  return worst;
}

/// The same for two parts' sums.
double max_relative_difference(const lucent::Accumulation& a, const lucent::Accumulation& b) {
  EXPECT_EQ(a.count, b.count);
  double worst = 0;
  for (size_t i = 0; i < a.sum.size() && i < b.sum.size(); ++i) {
    const double scale = std::max(std::abs(a.sum[i]), std::abs(b.sum[i]));
    if (scale > 0) worst = std::max(worst, std::abs(a.sum[i] - b.sum[i]) / scale);
  }
  return worst;
}

/// Starts `lucent args...` (stdout and stderr to /dev/null), waits until `path` exists (at most
/// 60 s, for a loaded machine), kills it with SIGKILL and reaps it. False (with a failure) when
/// it ended before the file appeared.
bool kill_once_written(const std::vector<std::string>& args, const std::string& path) {
  pid_t pid = ::fork();
  EXPECT_GE(pid, 0);
  if (pid == 0) {
    int null = ::open("/dev/null", O_RDWR);
    if (null < 0) ::_exit(126);
    ::dup2(null, 0);
    ::dup2(null, 1);
    ::dup2(null, 2);
    std::vector<char*> argv{const_cast<char*>("lucent")};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    ::execv(LUCENT_CLI_PATH, argv.data());
    ::_exit(127);
  }
  int status = 0;
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end && !fs::exists(path)) {
    if (::waitpid(pid, &status, WNOHANG) == pid) {
      ADD_FAILURE() << "lucent ended (status " << status << ") before writing " << path;
      return false;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ::kill(pid, SIGKILL);
  ::waitpid(pid, &status, 0);
  EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL)
      << "lucent was not killed (status " << status << "): the render ended first";
  return WIFSIGNALED(status);
}

/// The compression of the OpenEXR file at `path` (TINYEXR_COMPRESSIONTYPE_*).
int compression_of(const std::string& path) {
  const std::string bytes = lucent::test::read_file(path);
  return lucent::image_detail::probe_image(reinterpret_cast<const unsigned char*>(bytes.data()),
                                           bytes.size(), path, 1 << 24)
      .compression;
}

// (a) and (b): killed with SIGKILL once its first checkpoint exists, the render run again
// resumes from the checkpoint and writes the image of the uninterrupted render; the checkpoint
// in between holds exactly the samples [0, K) it claims, and is removed at the end.
TEST(Checkpoint, KilledRenderResumesToTheUninterruptedImage) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr", full = dir + "/full.exr";
  // about 1.5 s of rendering on this device (a CPU core: 12x10 at 100000 spp; a GPU ~100 times
  // more), measured by a render of 0.5 s: passes aim at 0.25 s, so the checkpoint every 0.2 s
  // first appears a fraction of the way in
  const double rate = lucent::test::cli_samples_per_second(scene, dir + "/cal.exr");
  ASSERT_GT(rate, 0) << "the calibration render failed";
  const std::uint64_t n =
      std::clamp<std::uint64_t>(std::uint64_t(rate * 1.5 / 120), 20000, std::uint64_t(1) << 24);
  const std::string spp = std::to_string(n);
  ASSERT_TRUE(kill_once_written(
      {"render", scene, "--spp", spp, "-o", out, "--checkpoint", ck, "--checkpoint-every", "0.2"},
      ck));
  EXPECT_FALSE(fs::exists(out));
  // (b) a part file of the samples [0, K), each of them in every pixel, and those samples: the
  // part of --samples 0:K
  const lucent::RenderPart part = lucent::read_render_part(ck);
  ASSERT_EQ(part.info.samples.size(), 1u);
  const std::uint64_t k = part.info.samples[0].end;
  EXPECT_EQ(part.info.samples[0].begin, 0u);
  EXPECT_GT(k, 0u);
  EXPECT_LT(k, n);
  EXPECT_EQ(part.info.requested, (std::vector<lucent::SampleRange>{{0, n}}));
  const std::string same = dir + "/same.exr";
  ASSERT_EQ(
      run_cli("render " + q(scene) + " -q --samples 0:" + std::to_string(k) + " -o " + q(same))
          .status,
      0);
  EXPECT_LT(max_relative_difference(part.acc, lucent::read_render_part(same).acc), 1e-5);
  // the checkpoint in PIZ (written in half ZIP's time: the render waits for it), the part of
  // --samples in ZIP (read in half PIZ's time)
  EXPECT_EQ(compression_of(ck), TINYEXR_COMPRESSIONTYPE_PIZ);
  EXPECT_EQ(compression_of(same), TINYEXR_COMPRESSIONTYPE_ZIP);

  // (a) the same command again: samples [K, N) only, the image of [0, N)
  CommandResult r = run_cli("render " + q(scene) + " --spp " + spp + " -o " + q(out) +
                            " --checkpoint " + q(ck) + " --checkpoint-every 0.2");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("lucent: resuming from " + ck + ", which holds samples [0, " +
                       std::to_string(k) + ")"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(ck));  // done with
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --spp " + spp + " -o " + q(full)).status, 0);
  const lucent::RenderResult resumed = lucent::read_render(out), single = lucent::read_render(full);
  EXPECT_EQ(resumed.samples, std::vector<std::uint32_t>(120, std::uint32_t(n)));
  EXPECT_LT(max_relative_difference(resumed, single), 1e-5);
}

// A checkpoint of part of the samples, or of all of them (a render killed after its last
// checkpoint, before its output): the image equals the single render's, and the checkpoint goes.
// A part of --samples 0:K is a checkpoint; one sample more or less is another image.
TEST(Checkpoint, ResumedImageEqualsTheSingleRender) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string full = dir + "/full.exr", ck = dir + "/ck.exr";
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --spp 64 -o " + q(full)).status, 0);
  const lucent::RenderResult single = lucent::read_render(full);
  for (const char* k : {"3", "64"}) {
    SCOPED_TRACE(k);
    ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:" + k + " -o " + q(ck)).status, 0);
    const std::string out = dir + "/out" + k + ".exr";
    CommandResult r =
        run_cli("render " + q(scene) + " -q --spp 64 --checkpoint " + q(ck) + " -o " + q(out));
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_FALSE(fs::exists(ck));
    EXPECT_LT(max_relative_difference(lucent::read_render(out), single), 1e-5);
  }
  // resumed with --time alone (no --spp: the session's part requested [0, 0) before its first
  // pass, which make_part refused: "make_part: requested samples [0, 0)"; the review's find)
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:3 -o " + q(ck)).status, 0);
  CommandResult timed = run_cli("render " + q(scene) + " -q --time 0.2 --checkpoint " + q(ck) +
                                " -o " + q(dir + "/timed.exr"));
  ASSERT_EQ(timed.status, 0) << timed.err;
  EXPECT_GT(lucent::read_render(dir + "/timed.exr").spp, 3u);
  EXPECT_FALSE(fs::exists(ck));
  // a PNG output too (the 8-bit image of the same means)
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:5 -o " + q(ck)).status, 0);
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --spp 64 -o " + q(dir + "/single.png")).status, 0);
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --spp 64 --checkpoint " + q(ck) + " -o " +
                    q(dir + "/resumed.png"))
                .status,
            0);
  // (within one 8-bit level, 0.0087 in linear at most: float pass sums, without fp64, may round a
  // value across a step)
  const lucent::Image a = lucent::read_image(dir + "/resumed.png"),
                      b = lucent::read_image(dir + "/single.png");
  ASSERT_EQ(a.rgb.size(), b.rgb.size());
  for (size_t i = 0; i < a.rgb.size(); ++i) EXPECT_NEAR(a.rgb[i], b.rgb[i], 0.009) << i;
}

// An output named as the checkpoint of a render in progress (its lock held): that render's next
// checkpoint write replaced the output with a part file, and its end removed it. Refused before
// rendering, by render and merge.
TEST(Checkpoint, AnOutputThatIsACheckpointInUseIsRefused) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir), shared = dir + "/shared.exr";
  const int fd = ::open((shared + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  // a lock of that name taken by other means (flock(1) around the command): no checkpoint's
  CommandResult other = run_cli("render " + q(scene) + " -q --spp 2 -o " + q(shared));
  EXPECT_EQ(other.status, 0) << other.err;
  fs::remove(shared);
  // a render's CheckpointLock: marked
  const ssize_t mark = sizeof lucent::io::kCheckpointLockMark - 1;
  ASSERT_EQ(::write(fd, lucent::io::kCheckpointLockMark, size_t(mark)), mark);
  const std::string refused = shared + ": is the checkpoint of a render in progress (" + shared +
                              ".lock is locked): give the output another name";
  // the only line of stderr, after "lucent: error: "
  auto error_line = [](const CommandResult& r) {
    EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
    const std::string prefix = "lucent: error: ";
    EXPECT_EQ(r.err.rfind(prefix, 0), 0u) << r.err;
    return r.err.substr(prefix.size(), r.err.find('\n') - prefix.size());
  };
  CommandResult r = run_cli("render " + q(scene) + " -q --spp 2 -o " + q(shared));
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(error_line(r), refused);
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:2 -o " + q(dir + "/p.exr")).status, 0);
  r = run_cli("merge -q " + q(dir + "/p.exr") + " -o " + q(shared));
  EXPECT_EQ(error_line(r), refused);
  EXPECT_FALSE(fs::exists(shared));
  ::close(fd);  // the render ended: the name is free
  EXPECT_EQ(run_cli("render " + q(scene) + " -q --spp 2 -o " + q(shared)).status, 0);
}

// Two renders given one checkpoint wrote over each other's samples (each run's work lost to the
// other's next write): a render holds <checkpoint>.lock while it runs, and a second one is
// refused with one line, before it reads the file, writing nothing. The lock goes with the
// finished render's checkpoint.
TEST(Checkpoint, ACheckpointInUseIsRefused) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr";
  {
    // another render's lock, as a running one holds it
    const int fd = ::open((ck + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
    CommandResult r =
        run_cli("render " + q(scene) + " -q --spp 8 --checkpoint " + q(ck) + " -o " + q(out));
    ::close(fd);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find("ck.exr: another render is using this checkpoint (" + ck +
                         ".lock is locked): give each render a checkpoint of its own"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(ck));
  }
  // free again: the render runs, and leaves neither its checkpoint nor the lock
  CommandResult r =
      run_cli("render " + q(scene) + " -q --spp 8 --checkpoint " + q(ck) + " -o " + q(out));
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
  EXPECT_FALSE(fs::exists(ck));
  EXPECT_FALSE(fs::exists(ck + ".lock"));
}

// A lock file that is a symbolic or hard link (planted in a shared directory) is refused, and the
// file it names is left as it was: the render truncated the link's target and wrote its mark in
// it, then removed the link (the parts campaign).
TEST(Checkpoint, ALockThatIsALinkIsRefusedAndWhatItNamesKept) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr", victim = dir + "/victim.txt";
  lucent::test::write_file(victim, "precious");
  for (const bool symbolic : {true, false}) {
    SCOPED_TRACE(symbolic ? "symbolic link" : "hard link");
    if (symbolic)
      fs::create_symlink(victim, ck + ".lock");
    else
      fs::create_hard_link(victim, ck + ".lock");
    CommandResult r =
        run_cli("render " + q(scene) + " -q --spp 4 --checkpoint " + q(ck) + " -o " + q(out));
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
    EXPECT_NE(r.err.find(ck + ".lock: the checkpoint's lock is " +
                         (symbolic ? std::string("a symbolic link")
                                   : std::string("a file of 2 names (hard links)")) +
                         ", not a file lucent made (remove it)"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(lucent::test::read_file(victim), "precious");
    EXPECT_TRUE(fs::is_symlink(ck + ".lock") == symbolic);
    EXPECT_FALSE(fs::exists(out));
    fs::remove(ck + ".lock");
  }
}

// The lock goes with the checkpoint: a render that fails before its first write (here a device
// that is not there, after the lock was taken) leaves no checkpoint, and no lock alone beside
// where it would be (it stayed for ever). A checkpoint refused stays, with its lock; a lock held
// by another render is not touched.
TEST(Checkpoint, ARenderThatWroteNoCheckpointLeavesNoLock) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr";
  CommandResult r = run_cli("render " + q(scene) + " -q --spp 8 --device 99 --checkpoint " + q(ck) +
                            " -o " + q(out));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_NE(r.err.find("--device 99"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(ck));
  EXPECT_FALSE(fs::exists(ck + ".lock"));
  // a checkpoint that is not a part file: refused, and kept as it was, with its lock
  lucent::test::write_file(ck, "not a part");
  r = run_cli("render " + q(scene) + " -q --spp 8 --checkpoint " + q(ck) + " -o " + q(out));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(lucent::test::read_file(ck), "not a part");
  EXPECT_TRUE(fs::exists(ck + ".lock"));
  fs::remove(ck);
  // another render's lock (held): refused, and the lock stays
  const int fd = ::open((ck + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
  r = run_cli("render " + q(scene) + " -q --spp 8 --checkpoint " + q(ck) + " -o " + q(out));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_TRUE(fs::exists(ck + ".lock"));
  ::close(fd);
  EXPECT_FALSE(fs::exists(out));
}

// SIGTERM: the output of the samples so far is written, and the checkpoint holds them too (it
// stays, for the next run), as the line before the last says.
TEST(Checkpoint, SigtermKeepsTheCheckpoint) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr", err = dir + "/err";
  // SIGTERM once the progress line shows the render loop running (from its first pass)
  const std::string script =
      std::string(lucent::test::kEarlyProgress) + " '" + std::string(LUCENT_CLI_PATH) +
      "' render " + q(scene) + " --spp 16000000 -o " + q(out) + " --checkpoint " + q(ck) + " 2>" +
      q(err) + " </dev/null & pid=$!; for i in $(seq 600); do grep -q " + "Msamples/s " + q(err) +
      " && break; sleep 0.1; done; kill -TERM " + "$pid; wait $pid";
  const int raw = std::system(("bash -c " + q(script)).c_str());
  const std::string text = lucent::test::read_file(err);
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 143) << text;
  const lucent::PartInfo info = lucent::read_part_info(ck);
  ASSERT_EQ(info.samples.size(), 1u) << text;
  const std::uint64_t k = info.samples[0].end;
  EXPECT_EQ(lucent::read_render(out).samples, std::vector<std::uint32_t>(120, std::uint32_t(k)));
  EXPECT_NE(text.find("lucent: " + ck + " holds samples [0, " + std::to_string(k) +
                      "): the same command resumes the render"),
            std::string::npos)
      << text;
}

// A render stopped after its every checkpoint write failed (here a file size limit: the PNG
// output fits, the part file of a noisy 500x400 film, whose doubles do not compress, does not) says
// last that no checkpoint holds its samples (it said only "wrote out.png with ... spp"; the warning
// before it alone told).
TEST(Checkpoint, AStoppedRenderWhoseCheckpointWasNeverWrittenSaysSo) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.png", err = dir + "/err";
  const std::string script =
      "ulimit -f 1500; '" + std::string(LUCENT_CLI_PATH) + "' render " + q(scene) +
      " --width 500 --height 400 --spp 16000000 -o " + q(out) + " --checkpoint " + q(ck) +
      " --checkpoint-every 0.05 2>" + q(err) +
      " </dev/null & pid=$!; for i in $(seq 600); do grep -q 'checkpoint not written' " + q(err) +
      " && break; sleep 0.1; done; kill -TERM $pid; wait $pid";
  lucent::test::write_file(dir + "/stop.sh", script + "\n");
  const int raw = std::system(("bash " + q(dir + "/stop.sh")).c_str());
  const std::string text = lucent::test::read_file(err);
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 143) << text;
  EXPECT_NE(text.find("lucent: warning: checkpoint not written: " + ck +
                      ": cannot write (File too large)"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("lucent: no checkpoint holds the samples (" + ck +
                      " not written): the same command renders them again\n"),
            std::string::npos)
      << text;
  EXPECT_TRUE(fs::exists(out)) << text;
  EXPECT_FALSE(fs::exists(ck)) << text;
}

// A checkpoint removed after its last write (here with its directory, so that the writes since
// fail) holds nothing: the last line says so (it said the file that was gone held the samples).
// The writes that fail in a row, every 0.1 s for a second, say so once (they said it at each).
TEST(Checkpoint, ACheckpointRemovedSinceItsLastWriteIsNotSaidToHoldTheSamples) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string sub = dir + "/sub", ck = sub + "/ck.exr", out = dir + "/out.exr",
                    err = dir + "/err";
  fs::create_directories(sub);
  // SIGTERM once a periodic checkpoint was written and its directory removed
  const std::string script =
      "'" + std::string(LUCENT_CLI_PATH) + "' render " + q(scene) + " --spp 16000000 -o " + q(out) +
      " --checkpoint " + q(ck) + " --checkpoint-every 0.1 2>" + q(err) +
      " </dev/null & pid=$!; for i in $(seq 600); do test -f " + q(ck) +
      " && break; sleep 0.1; done; rm -rf " + q(sub) + "; sleep 1; kill -TERM " + "$pid; wait $pid";
  const int raw = std::system(("bash -c " + q(script)).c_str());
  const std::string text = lucent::test::read_file(err);
  ASSERT_TRUE(WIFEXITED(raw) && WEXITSTATUS(raw) == 143) << text;
  const std::string warning = "lucent: warning: checkpoint not written: " + ck;
  const size_t first = text.find(warning);
  EXPECT_NE(first, std::string::npos) << text;
  EXPECT_EQ(text.find(warning, first + 1), std::string::npos) << text;
  EXPECT_NE(
      text.find("lucent: no checkpoint holds the samples (" + ck + ", written with samples [0, "),
      std::string::npos)
      << text;
  EXPECT_NE(text.find("), no longer exists): the same command renders them again\n"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("holds samples"), std::string::npos) << text;
  EXPECT_TRUE(fs::exists(out)) << text;  // (the output keeps what was rendered)
}

// (c) a checkpoint of another image (seed, scene, film), of other samples or of more than the
// render asks for: one line naming it, status 1, no output, the checkpoint untouched.
TEST(Checkpoint, CheckpointOfAnotherRenderIsRefused) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string other = noisy_scene(dir, "other.json", 0.6);
  const std::string ck = dir + "/ck.exr", later = dir + "/later.exr", out = dir + "/out.png";
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:4 -o " + q(ck)).status, 0);
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 4:8 -o " + q(later)).status, 0);
  const std::string bytes = lucent::test::read_file(ck);
  // its pixels damaged (the last bytes: the sums' last chunk): the header is compared with the
  // render's first, and the pixels read after (they were read first: a forged header of another
  // film took 13 GB and a minute before the mismatch was said), and refused there
  const std::string damaged = dir + "/damaged.exr";
  std::string broken = bytes;
  for (std::size_t i = broken.size() - 16; i < broken.size(); ++i) broken[i] = char(~broken[i]);
  lucent::test::write_file(damaged, broken);
  const struct {
    std::string args, error;
  } cases[] = {
      {q(scene) + " --width 13 --checkpoint " + q(damaged),
       damaged + ": film 12x10 differs from " + scene + "'s 13x10"},
      {q(scene) + " --checkpoint " + q(damaged), damaged + ": "},
      {q(scene) + " --seed 9 --checkpoint " + q(ck),
       ck + ": seed 3 differs from " + scene + "'s 9"},
      {q(other) + " --checkpoint " + q(ck), ck + ": scene hash "},
      {q(scene) + " --width 13 --checkpoint " + q(ck),
       ck + ": film 12x10 differs from " + scene + "'s 13x10"},
      {q(scene) + " --spp 2 --checkpoint " + q(ck),
       ck + ": holds 4 samples per pixel, more than the 2 this render asks for"},
      {q(scene) + " --checkpoint " + q(later),
       later + ": holds samples [4, 8), not a checkpoint's [0, K)"},
      {q(scene) + " --checkpoint " + q(scene + ".exr"), ""},  // (none yet: a fresh render)
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    CommandResult r = run_cli("render " + c.args + " -q -o " + q(out));
    if (c.error.empty()) {
      EXPECT_EQ(r.status, 0) << r.err;
      fs::remove(out);
      continue;
    }
    EXPECT_EQ(r.status, 1);
    EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("lucent: error: " + c.error, 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(out));
  }
  EXPECT_EQ(lucent::test::read_file(ck), bytes);
}

// (d) what a checkpoint cannot hold, or options that do nothing: one line, nothing written.
TEST(Checkpoint, UnsupportedCombinationsAreRefused) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = q(dir + "/ck.exr"), out = dir + "/out.exr";
  const struct {
    std::string args, error;
    int status;
  } cases[] = {
      {"--checkpoint " + ck + " --aov albedo", "--checkpoint is not supported with --aov", 1},
      {"--checkpoint " + ck + " --target-error 0.01",
       "--checkpoint is not supported with --target-error", 1},
      {"--checkpoint " + ck + " --reference", "--checkpoint is not supported with --reference", 1},
      {"--checkpoint " + ck + " --samples 0:4", "--checkpoint is not supported with --samples", 1},
      {"--checkpoint-every 5", "--checkpoint-every is how often --checkpoint writes", 1},
      {"--checkpoint " + q(dir + "/ck.png"), dir + "/ck.png: --checkpoint writes a part file", 1},
      {"--checkpoint " + q(out), out + ": is the output too", 1},
      {"--checkpoint " + ck + " --checkpoint-every 0",
       "--checkpoint-every: must be in (0, 1e7] seconds, got 0", 2},
      {"--checkpoint " + ck + " --checkpoint-every 2e7", "--checkpoint-every: must be in", 2},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.args);
    CommandResult r = run_cli("render " + q(scene) + " -q -o " + q(out) + " " + c.args);
    EXPECT_EQ(r.status, c.status);
    EXPECT_EQ(lucent::test::count_lines(r.err), 1) << r.err;
    EXPECT_EQ(r.err.rfind("lucent: error: " + c.error, 0), 0u) << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_FALSE(fs::exists(dir + "/ck.exr"));
  }
  // light-traced caustics, in a scene with a mirror; a scene without a mirror or smooth glass
  // renders none, and its checkpoints and parts are accepted (they were refused all the same)
  std::string text = lucent::test::read_file(scene);
  const std::string sphere = R"("material": "m"}])";
  ASSERT_NE(text.find(sphere), std::string::npos);
  text.replace(text.find(sphere), sphere.size(), R"("material": "mirror"}])");
  text.replace(text.find(R"("materials": {)"), 14,
               R"("materials": {"mirror": {"type": "mirror"}, )");
  const std::string mirror = dir + "/mirror.json";
  lucent::test::write_file(mirror, text);
  CommandResult r =
      run_cli("render " + q(mirror) + " -q -o " + q(out) + " --checkpoint " + ck + " --caustics");
  EXPECT_EQ(r.status, 1);
  EXPECT_EQ(r.err, "lucent: error: " + mirror +
                       ": integrator.caustics: a checkpoint (a part file) cannot hold "
                       "light-traced caustics yet; render without --checkpoint, or with "
                       "--no-caustics\n");
  EXPECT_FALSE(fs::exists(out));
  r = run_cli("render " + q(mirror) + " -q -o " + q(dir + "/part.exr") +
              " --samples 0:2 --caustics");
  EXPECT_EQ(r.status, 1);
  EXPECT_NE(r.err.find("part files and MPI ranks cannot hold light-traced caustics"),
            std::string::npos)
      << r.err;
  r = run_cli("render " + q(scene) + " -q -o " + q(out) + " --checkpoint " + ck + " --caustics");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(fs::exists(out));
  r = run_cli("render " + q(scene) + " -q -o " + q(dir + "/part.exr") +
              " --samples 0:2 --caustics");
  EXPECT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(lucent::read_part_info(dir + "/part.exr").samples,
            (std::vector<lucent::SampleRange>{{0, 2}}));
}

// The output under another spelling of the checkpoint's name (./out.exr, out.exr: libstdc++'s
// weakly_canonical made one absolute and left the other relative) is refused; it was accepted,
// and the finished render removed its output as its checkpoint (status 0, no image).
TEST(Checkpoint, OutputUnderAnotherNameIsRefusedNeverRemoved) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string in_dir = "cd " + q(dir) + " &&";
  for (const auto& [out, ck] : std::vector<std::pair<std::string, std::string>>{
           {"./out.exr", "out.exr"}, {"out.exr", "./out.exr"}, {"out.exr", "sub/../out.exr"}}) {
    SCOPED_TRACE(out + " " + ck);
    fs::create_directories(dir + "/sub");
    CommandResult r =
        run_cli("render scene.json -q -o " + q(out) + " --checkpoint " + q(ck), in_dir);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_EQ(r.err, "lucent: error: " + ck +
                         ": is the output too: give --checkpoint a file of "
                         "its own\n");
    EXPECT_FALSE(fs::exists(dir + "/out.exr"));
  }
}

// The summary line of a resumed render: its spp are the image's (the checkpoint's samples
// named), its time and rates this run's. A checkpoint of all the samples renders none: 0
// Msamples/s (several devices divided the checkpoint's samples by this run's wall time of a
// millisecond: 59076.92 Msamples/s; one, by the checkpoint's time).
TEST(Checkpoint, SummaryRatesAreThisRunsOwn) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr";
  for (const std::string env : {"", "LUCENT_DEVICE=0,0"}) {
    SCOPED_TRACE(env);
    if (!env.empty() &&
        run_cli("render " + q(scene) + " -q -o " + q(dir + "/two.exr"), env).status != 0)
      continue;  // (two contexts on device 0 not supported here)
    ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:64 -o " + q(ck)).status, 0);
    const std::string out = dir + "/out.exr";
    CommandResult r =
        run_cli("render " + q(scene) + " --spp 64 --checkpoint " + q(ck) + " -o " + q(out), env);
    ASSERT_EQ(r.status, 0) << r.err;
    EXPECT_NE(r.err.find(out + ": 12x10, 64 spp (64 of them from " + ck + ") in "),
              std::string::npos)
        << r.err;
    EXPECT_NE(r.err.find(" (0.00 Msamples/s, 0.00 Mrays/s, "), std::string::npos) << r.err;
  }
}

// A render killed while it wrote its checkpoint (SIGKILL, the OOM killer) left the write's
// temporary file, as large as the checkpoint, for ever. The next render that holds the checkpoint's
// lock removes the temporary files of its checkpoint's writes, and no other file.
TEST(Checkpoint, TemporaryFilesOfAKilledWriteAreRemoved) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr";
  const std::vector<std::string> stale = {".ck.exr.tmp-123456-0", ".ck.exr.tmp-7-12"};
  const std::vector<std::string> kept = {".ck.exr.tmp-12x-0", ".ck.exr.tmp-",   ".ck.exr.tmp-1-",
                                         ".out.exr.tmp-7-0",  "ck.exr.tmp-7-0", ".ck.exr.tmp-1-2.x",
                                         ".ck.exr.bak"};
  for (const std::string& name : stale) lucent::test::write_file(dir + "/" + name, "partial");
  for (const std::string& name : kept) lucent::test::write_file(dir + "/" + name, "other");
  CommandResult r =
      run_cli("render " + q(scene) + " -q --spp 8 -o " + q(out) + " --checkpoint " + q(ck));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const std::string& name : stale) EXPECT_FALSE(fs::exists(dir + "/" + name)) << name;
  for (const std::string& name : kept) EXPECT_TRUE(fs::exists(dir + "/" + name)) << name;
}

// A checkpoint given as a symbolic link is the file it leads to, which its writes replace: locked
// there (a lock per name let a render given the link and one given the target write one file, and
// remove each other's write in progress as a stale temporary), and removed there once the output
// is written (the link was removed, and the finished checkpoint stayed for a later render of the
// target to resume from).
TEST(Checkpoint, ASymbolicLinkIsTheCheckpointItLeadsTo) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string real = dir + "/real/ck.exr", link = dir + "/link.exr", out = dir + "/out.exr";
  fs::create_directory(dir + "/real");
  fs::create_symlink("real/ck.exr", link);
  const std::string live = dir + "/real/.ck.exr.tmp-999999-0";  // the other render's write
  lucent::test::write_file(live, "in progress");
  {
    // another render given the target holds its lock
    const int fd = ::open((real + ".lock").c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0644);
    ASSERT_GE(fd, 0);
    ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);
    CommandResult r =
        run_cli("render " + q(scene) + " -q --spp 8 --checkpoint " + q(link) + " -o " + q(out));
    ::close(fd);
    EXPECT_EQ(r.status, 1) << r.err;
    EXPECT_NE(r.err.find("link.exr: another render is using this checkpoint (" + real +
                         ".lock is locked)"),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(out));
    EXPECT_TRUE(fs::exists(live));
    EXPECT_FALSE(fs::exists(link + ".lock"));
  }
  fs::remove(live);
  fs::remove(real + ".lock");
  // a checkpoint of [0, 4) at the target: resumed through the link, then removed there
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:4 -o " + q(real)).status, 0);
  CommandResult r =
      run_cli("render " + q(scene) + " --spp 8 --checkpoint " + q(link) + " -o " + q(out));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("resuming from " + link + ", which holds samples [0, 4)"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(", 8 spp (4 of them from " + link + ")"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(real)) << "the finished checkpoint stayed";
  EXPECT_FALSE(fs::exists(real + ".lock"));
  EXPECT_TRUE(fs::is_symlink(link)) << "the link is the user's";
}

// remove_stale_temporaries removes only the regular files a write of its checkpoint makes: not a
// symbolic link of such a name (it followed links, and removed one that led to a regular file),
// nor a directory; names with glob and regex characters are matched as they are.
TEST(Checkpoint, StaleTemporariesAreOnlyTheWritesOwnFiles) {
  const std::string dir = lucent::test::temp_dir();
  const std::string name = "c[k]*.+(1)?.exr", ck = dir + "/" + name;
  lucent::test::write_file(dir + "/precious.exr", "someone's");
  const std::string stale = "." + name + ".tmp-12-0";
  lucent::test::write_file(dir + "/" + stale, "partial");
  fs::create_symlink("precious.exr", dir + "/." + name + ".tmp-13-0");
  fs::create_symlink("nowhere.exr", dir + "/." + name + ".tmp-14-0");
  fs::create_directory(dir + "/." + name + ".tmp-15-0");
  lucent::test::write_file(dir + "/.ck.exr.tmp-16-0", "another name's");  // ([k]* as a glob)
  EXPECT_EQ(lucent::io::remove_stale_temporaries(ck), 1);
  EXPECT_FALSE(fs::exists(dir + "/" + stale));
  EXPECT_TRUE(fs::is_symlink(dir + "/." + name + ".tmp-13-0"));
  EXPECT_TRUE(fs::is_symlink(dir + "/." + name + ".tmp-14-0"));
  EXPECT_TRUE(fs::is_directory(dir + "/." + name + ".tmp-15-0"));
  EXPECT_TRUE(fs::exists(dir + "/.ck.exr.tmp-16-0"));
  EXPECT_EQ(lucent::test::read_file(dir + "/precious.exr"), "someone's");
}

// A write in progress holds an flock on its temporary file (io::open_temp), but
// remove_stale_temporaries removed every file of a temporary's name, a write in progress too (of
// another process that writes the name: its rename then failed). Only files no process holds go.
TEST(Checkpoint, StaleTemporariesLeaveAWriteInProgress) {
  const std::string dir = lucent::test::temp_dir();
  const std::string ck = dir + "/ck.exr";
  const std::string held = dir + "/.ck.exr.tmp-20-0", left = dir + "/.ck.exr.tmp-21-0";
  lucent::test::write_file(held, "a write in progress");
  lucent::test::write_file(left, "a killed write's");
  const int fd = ::open(held.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::flock(fd, LOCK_EX | LOCK_NB), 0);  // (another open file: its lock conflicts)
  EXPECT_EQ(lucent::io::remove_stale_temporaries(ck), 1);
  EXPECT_TRUE(fs::exists(held));
  EXPECT_FALSE(fs::exists(left));
  ::close(fd);
  EXPECT_EQ(lucent::io::remove_stale_temporaries(ck), 1);
  EXPECT_FALSE(fs::exists(held));
}

// The progress line of a resumed render counts its checkpoint's samples ("20 + 1234 spp") and
// its percentage is of the whole render; it counted this run's samples alone.
TEST(Checkpoint, ProgressOfAResumedRenderCountsTheCheckpoint) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = noisy_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.exr";
  // a checkpoint of a quarter of the samples (about 1.3 s), then 1.5 s of rendering (--time) of
  // what would take 4 s: the progress line starts after 1 s, and a machine up to 4 times faster
  // than at the calibration still prints one (the rest in 1.5 s, without --time, did not under a
  // changing load)
  const double rate = lucent::test::cli_samples_per_second(scene, dir + "/cal.exr");
  ASSERT_GT(rate, 0) << "the calibration render failed";
  const std::uint64_t n = std::clamp<std::uint64_t>(std::uint64_t(rate * 4 / 120 * 4 / 3), 20000,
                                                    std::uint64_t(1) << 24);
  const std::uint64_t k = n / 4;
  ASSERT_EQ(run_cli("render " + q(scene) + " -q --samples 0:" + std::to_string(k) + " -o " + q(ck))
                .status,
            0);
  CommandResult r = run_cli("render " + q(scene) + " --spp " + std::to_string(n) + " -o " + q(out) +
                            " --checkpoint " + q(ck) + " --time 1.5");
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string head = "%  " + std::to_string(k) + " + ";
  const size_t line = r.err.find(head);
  ASSERT_NE(line, std::string::npos) << r.err;
  // "NN.N%  K + D spp": at least the checkpoint's share of the render
  const size_t start =
      r.err.rfind('\n', line) == std::string::npos ? 0 : r.err.rfind('\n', line) + 1;
  const double percent = std::atof(r.err.substr(start, line - start).c_str());
  EXPECT_GE(percent, 100.0 * double(k) / double(n) - 0.05) << r.err;
  EXPECT_NE(r.err.find(" spp  ", line), std::string::npos) << r.err;
}

// The output's write fails after a complete render (a full disk; here a file size limit of 1.5 MB,
// which the 2.4 MB PFM exceeds and the 75 KB checkpoint does not): the samples go to the
// checkpoint, all of them (it held none: the default --checkpoint-every is 300 s, and a render
// that ran that long lost up to 300 s of work), and two lines say so. The same command then
// renders nothing and writes the image of the uninterrupted render.
TEST(Checkpoint, FailedOutputWriteKeepsTheSamplesInTheCheckpoint) {
  const std::string dir = lucent::test::temp_dir();
  const std::string scene = lucent::test::flat_lamp_scene(dir);
  const std::string ck = dir + "/ck.exr", out = dir + "/out.pfm", full = dir + "/full.pfm";
  // (first: the kernel caches are filled, whose files the limit would refuse)
  ASSERT_EQ(run_cli("render " + q(scene) + " -q -o " + q(full)).status, 0);
  // (bash's unit, KiB: sh's may be 512 bytes)
  const std::string limited = dir + "/limited.sh";
  lucent::test::write_file(limited, "ulimit -f 1500\nexec \"$@\"\n");
  CommandResult r = run_cli("render " + q(scene) + " -q -o " + q(out) + " --checkpoint " + q(ck),
                            "bash " + q(limited));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err, "lucent: error: " + out + ": cannot write (File too large)\nlucent: " + ck +
                       " holds all the samples, [0, 4): the same command writes the output\n");
  EXPECT_FALSE(fs::exists(out));
  ASSERT_TRUE(fs::exists(ck)) << r.err;
  EXPECT_EQ(lucent::read_part_info(ck).samples, (std::vector<lucent::SampleRange>{{0, 4}}));

  r = run_cli("render " + q(scene) + " -o " + q(out) + " --checkpoint " + q(ck));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.err.find("lucent: resuming from " + ck + ", which holds samples [0, 4)"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(", 4 spp (4 of them from " + ck + ") in 0.000 s ("), std::string::npos)
      << r.err;  // (nothing rendered)
  EXPECT_FALSE(fs::exists(ck));
  EXPECT_FALSE(fs::exists(ck + ".lock"));
  const lucent::Image resumed = lucent::read_image(out), single = lucent::read_image(full);
  ASSERT_EQ(resumed.rgb.size(), single.rgb.size());
  double worst = 0;
  for (size_t i = 0; i < resumed.rgb.size(); ++i) {
    const double x = resumed.rgb[i], y = single.rgb[i];
    if (std::max(std::abs(x), std::abs(y)) > 0)
      worst = std::max(worst, std::abs(x - y) / std::max(std::abs(x), std::abs(y)));
  }
  EXPECT_LT(worst, 1e-5);

  // a checkpoint over the limit too (a noisy image's: its doubles do not compress): a warning
  // says so, and the last line that no file holds the samples
  const std::string noisy = noisy_scene(dir);
  const std::string size = " --width 500 --height 400 --spp 2";
  ASSERT_EQ(run_cli("render " + q(noisy) + " -q" + size + " -o " + q(full)).status, 0);
  const std::string noisy_out = dir + "/noisy.pfm";
  r = run_cli(
      "render " + q(noisy) + " -q" + size + " -o " + q(noisy_out) + " --checkpoint " + q(ck),
      "bash " + q(limited));
  EXPECT_EQ(r.status, 1) << r.err;
  EXPECT_EQ(r.err,
            "lucent: error: " + noisy_out + ": cannot write (File too large)\n" +
                "lucent: warning: checkpoint not written: " + ck +
                ": cannot write (File too large)\nlucent: no checkpoint holds the samples (" + ck +
                " not written): the same command renders them again\n");
  EXPECT_FALSE(fs::exists(noisy_out));
  EXPECT_FALSE(fs::exists(ck));
}

}  // namespace

}  // namespace test_checkpoint
