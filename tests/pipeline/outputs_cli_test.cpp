// Every subcommand's outputs (docs/outputs.md): paths that cannot be outputs are
// refused before any work with exit 1 and a message naming them; existing
// outputs stay byte for byte as they were unless the run completes; temporary
// files never stay behind, also after SIGINT, SIGTERM and SIGHUP (exit 130, 143,
// 129) at several points of a run; permissions of a replaced file are kept.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <spawn.h>
#include <sys/file.h>
#include <sys/mount.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>

#include "terrain/mesh_io.h"
#include "terrain/raster_io.h"
#include "tests/cli_fixture.h"
#include "tests/test_files.h"

extern char** environ;

namespace fs = std::filesystem;

namespace {

using namespace drift::testing;
using Result = RunResult;

fs::path test_dir() { return drift::testing::test_dir("drift_outputs_cli"); }

std::vector<std::string> split(const std::string& args) {
  std::istringstream in(args);
  std::vector<std::string> v;
  for (std::string w; in >> w;) v.push_back(w);
  return v;
}

// Where a run stops itself so that a test acts at exactly that point
// (terrain/temp_registry.h): at the n-th output write or the n-th progress
// report of the computation. n = 0: no stop.
struct Stop {
  enum Point { write, progress } point = write;
  int n = 0;
};

// Runs drift with `args` (split at spaces). With a stop, `at_stop` runs once
// the run has stopped itself, then `sig` (if any) is sent and the run continued;
// with a signal the run waits for it there (DRIFT_TEST_AWAIT_SIGNAL) rather than
// racing on. No sleeps: where the run is when the signal comes is fixed.
Result drift(const std::string& args, const fs::path& dir, Stop stop = {}, int sig = 0,
             const std::function<void()>& at_stop = {}) {
  std::vector<std::string> words = split(args);
  words.insert(words.begin(), DRIFT_EXECUTABLE);
  std::vector<char*> argv;
  for (auto& w : words) argv.push_back(w.data());
  argv.push_back(nullptr);
  std::vector<std::string> env_strings;
  for (char** e = environ; *e; ++e) env_strings.emplace_back(*e);
  if (stop.n > 0) {
    env_strings.push_back(std::string(stop.point == Stop::write ? "DRIFT_TEST_STOP_AT_WRITE="
                                                                : "DRIFT_TEST_STOP_AT_PROGRESS=") +
                          std::to_string(stop.n));
    if (sig) env_strings.push_back("DRIFT_TEST_AWAIT_SIGNAL=1");
  }
  std::vector<char*> envp;
  for (auto& e : env_strings) envp.push_back(e.data());
  envp.push_back(nullptr);
  const fs::path log = dir.parent_path() / (dir.filename().string() + ".log");
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&actions, 1, 2);
  pid_t pid = 0;
  EXPECT_EQ(posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), envp.data()), 0);
  posix_spawn_file_actions_destroy(&actions);
  int status = 0;
  bool ended = false;
  if (stop.n > 0) {
    waitpid(pid, &status, WUNTRACED);
    ended = !WIFSTOPPED(status);
    EXPECT_FALSE(ended) << args << ": ended before its stop point";
    if (!ended) {
      if (at_stop) at_stop();
      if (sig) kill(pid, sig);
      kill(pid, SIGCONT);
    }
  }
  if (!ended) waitpid(pid, &status, 0);
  Result r;
  r.status = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  r.log = slurp(log);
  return r;
}

// Files in `dir` whose names start with '.' (the temporary files' names do).
std::vector<std::string> hidden_files(const fs::path& dir) {
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir)) {
    if (e.path().filename().string()[0] == '.') found.push_back(e.path().string());
  }
  return found;
}

// A small metric DEM, a scene rendering it, two tiles and a PNG of it.
struct Inputs {
  fs::path dir, dem, scene, png, tile0, tile1, marks_ground, track;
};

// Made once per build of drift and shared by the test processes (CTest runs
// them in parallel): a lock file serialises the making, a stamp records for
// which drift binary they were made.
Inputs make_inputs() {
  static Inputs made;
  if (!made.dir.empty()) return made;
  made.dir = fs::path(DRIFT_BINARY_DIR) / "tests" / "outputs_cli_inputs";
  made.dem = made.dir / "dem.tif";
  made.scene = made.dir / "scene.toml";
  made.png = made.dir / "frame.png";
  made.tile0 = made.dir / "t0.exr";
  made.tile1 = made.dir / "t1.exr";
  made.marks_ground = made.dir / "marks_ground.tif";
  made.track = made.dir / "track.toml";
  fs::create_directories(made.dir);
  const int lock = open((made.dir / "lock").c_str(), O_RDWR | O_CREAT, 0644);
  flock(lock, LOCK_EX);
  const std::string stamp =
      std::to_string(fs::last_write_time(DRIFT_EXECUTABLE).time_since_epoch().count());
  if (slurp(made.dir / "stamp") != stamp) {
    drift::terrain::HeightField g(32, 32, 0.0f, drift::terrain::local_georeference(10.0));
    for (int r = 0; r < 32; ++r)
      for (int x = 0; x < 32; ++x) g(x, r) = 100.0f + 3.0f * static_cast<float>(x + (r % 7));
    drift::terrain::write_geotiff(g, made.dem);
    put(made.scene, "[terrain]\nraster = \"dem.tif\"\n[sun]\nazimuth = 120\nelevation = 35\n");
    const std::string base = "render " + made.scene.string() + " --size 16x8 --spp 1 ";
    EXPECT_EQ(drift(base + "-o " + made.png.string(), made.dir / "r0").status, 0);
    EXPECT_EQ(drift(base + "--tile 0/2 -o " + made.tile0.string(), made.dir / "r1").status, 0);
    EXPECT_EQ(drift(base + "--tile 1/2 -o " + made.tile1.string(), made.dir / "r2").status, 0);
    // A ball pressed into 1 cm cells (as tests/marks/marks_cli_test.cpp).
    drift::terrain::HeightField m(32, 32, 2000.0f, drift::terrain::local_georeference(0.01));
    m.geo().geotransform[0] = 600000.0;
    m.geo().geotransform[3] = 4000000.0;
    drift::terrain::write_geotiff(m, made.marks_ground);
    put(made.track,
        "step = 0.1\n[[objects]]\nmesh = \"" DRIFT_SOURCE_DIR
        "/data/objects/ball.obj\"\nscale = 0.2\n"
        "[[objects.keyframes]]\ntime = 0.0\nposition = [600000.16, 3999999.84, 2000.04]\n"
        "[[objects.keyframes]]\ntime = 0.2\nposition = [600000.16, 3999999.84, 2000.01]\n");
    put(made.dir / "stamp", stamp);
  }
  flock(lock, LOCK_UN);
  close(lock);
  return made;
}

// One run of each subcommand that writes: its arguments with OUT where the
// (first) output goes, the output's extension and the input it reads first.
struct Command {
  std::string name, args, ext;
  fs::path input;
};

const std::vector<Command>& commands() {
  const Inputs in = make_inputs();
  const std::string dem = in.dem.string(), png = in.png.string();
  static const std::vector<Command> all = {
      {"import", "import " + dem + " -o OUT", ".tif", in.dem},
      {"dunes", "dunes --size 16 --steps 2 -o OUT", ".tif", {}},
      {"snow cover", "snow cover " + dem + " --radius-cells 3 -o OUT", ".tif", in.dem},
      {"snow fall", "snow fall " + dem + " --maps 1 --spread 0 -o OUT", ".tif", in.dem},
      {"render", "render " + in.scene.string() + " --size 16x8 --spp 1 -o OUT", ".png", in.scene},
      {"merge", "merge " + in.tile0.string() + " " + in.tile1.string() + " -o OUT", ".exr",
       in.tile0},
      {"compare", "compare " + png + " " + png + " --diff OUT", ".png", in.png},
      {"sheet", "sheet " + png + " -o OUT", ".png", in.png},
      {"marks", "marks " + in.marks_ground.string() + " --track " + in.track.string() + " -o OUT",
       ".tif", in.marks_ground},
      {"mesh", "mesh " + dem + " --step 4 -o OUT", ".glb", in.dem},
  };
  return all;
}

const std::vector<std::string> kCommandNames = {"import", "dunes", "snow cover", "snow fall",
                                                "render", "merge", "compare",    "sheet",
                                                "marks",  "mesh"};

// The tests below run once per subcommand that writes (named in the test's name).
class EachCommand : public ::testing::TestWithParam<std::string> {
 protected:
  const Command& command() const {
    for (const Command& c : commands()) {
      if (c.name == GetParam()) return c;
    }
    throw std::runtime_error("no command " + GetParam());
  }
};

std::string test_name(const ::testing::TestParamInfo<std::string>& info) {
  std::string name = info.param;
  for (char& ch : name) ch = ch == ' ' ? '_' : ch;
  return name;
}

std::string with_output(const Command& c, const fs::path& out) {
  std::string args = c.args;
  args.replace(args.find("OUT"), 3, out.string());
  return args;
}

TEST_P(EachCommand, WritesAndKeepsPermissions) {
  {
    const Command& c = command();
    const fs::path d = test_dir(), out = d / ("out" + c.ext);
    put(out, "old");
    fs::permissions(out, fs::perms(0640));
    const Result r = drift(with_output(c, out), d);
    EXPECT_EQ(r.status, 0) << c.name << ": " << r.log;
    EXPECT_NE(slurp(out), "old") << c.name;
    EXPECT_EQ(fs::status(out).permissions() & fs::perms::all, fs::perms(0640)) << c.name;
    EXPECT_TRUE(hidden_files(d).empty()) << c.name;
  }
}

TEST_P(EachCommand, WritesNamesUpToTheFileSystemLimit) {
  {
    const Command& c = command();
    const fs::path d = test_dir();
    const fs::path out = d / (std::string(255 - c.ext.size(), 'n') + c.ext);  // 255 bytes
    const Result r = drift(with_output(c, out), d);
    EXPECT_EQ(r.status, 0) << c.name << ": " << r.log;
    EXPECT_TRUE(fs::exists(out)) << c.name;
    EXPECT_TRUE(hidden_files(d).empty()) << c.name;
  }
}

// Every class of path that is not a possible output, for every subcommand:
// exit 1, the message names the path, nothing is touched.
TEST_P(EachCommand, RefusesPathsThatCannotBeOutputs) {
  {
    const Command& c = command();
    const fs::path d = test_dir();
    const fs::path target = d / ("real" + c.ext), link = d / ("link" + c.ext);
    put(target, "keep me");
    fs::create_symlink(target, link);
    const fs::path fifo = d / ("fifo" + c.ext), folder = d / ("folder" + c.ext);
    ASSERT_EQ(mkfifo(fifo.c_str(), 0644), 0);
    fs::create_directory(folder);
    std::map<std::string, fs::path> refused = {
        {"device", "/dev/null"},
        {"fifo", fifo},
        {"directory", folder},
        {"symlink", link},
        {"missing folder", d / "no" / ("x" + c.ext)},
        {"name too long", d / (std::string(256, 'n') + c.ext)}};
    if (!c.input.empty()) refused["input"] = c.input;
    const std::string input_before = c.input.empty() ? "" : slurp(c.input);
    for (const auto& [what, out] : refused) {
      const Result r = drift(with_output(c, out), d);
      EXPECT_EQ(r.status, 1) << c.name << ", " << what << ": " << r.log;
      const std::string shown = out.filename().string().substr(0, 40);
      EXPECT_NE(r.log.find(shown), std::string::npos) << c.name << ", " << what << ": " << r.log;
    }
    struct stat st {};
    ASSERT_EQ(stat("/dev/null", &st), 0);
    EXPECT_TRUE(S_ISCHR(st.st_mode)) << c.name << " replaced /dev/null";
    EXPECT_TRUE(fs::is_symlink(link)) << c.name;
    EXPECT_EQ(slurp(target), "keep me") << c.name;
    EXPECT_TRUE(fs::is_fifo(fifo) && fs::is_directory(folder)) << c.name;
    if (!c.input.empty()) {
      EXPECT_EQ(slurp(c.input), input_before) << c.name;
    }
    EXPECT_TRUE(hidden_files(d).empty()) << c.name;
  }
}

// A full disk: a small tmpfs filled to the last page before the run. Every
// writer's failure is caught (OpenImageIO's PNG writer had left a truncated PNG
// over the old file and exit 0), the run exits 1 naming the output, the old
// file is left as it was and no temporary file stays. Skipped where a tmpfs
// cannot be mounted (not root, or in a container that forbids it).
class FullDisk {
 public:
  explicit FullDisk(const fs::path& dir) : dir_(dir) {
    fs::create_directories(dir_);
    mounted_ = mount("tmpfs", dir_.c_str(), "tmpfs", 0, "size=64k") == 0;
  }
  ~FullDisk() {
    if (mounted_) umount(dir_.c_str());
  }
  bool mounted() const { return mounted_; }
  // Puts `old` at `path`, then fills the file system to its last byte.
  void fill_after(const fs::path& path, const std::string& old) {
    for (const auto& e : fs::directory_iterator(dir_)) fs::remove_all(e.path());
    put(path, old);
    const int fd = open((dir_ / "filler").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
    const std::string block(4096, 'x');
    while (write(fd, block.data(), block.size()) > 0) {
    }
    while (write(fd, "x", 1) > 0) {
    }
    close(fd);
  }

 private:
  fs::path dir_;
  bool mounted_ = false;
};

TEST_P(EachCommand, FullDiskFailsAndKeepsTheOldOutput) {
  const Command& c = command();
  const fs::path d = test_dir();
  FullDisk disk(d / "full");
  if (!disk.mounted()) GTEST_SKIP() << "cannot mount a tmpfs here (needs root): not tested";
  std::vector<std::pair<std::string, fs::path>> runs = {
      {with_output(c, d / "full" / ("out" + c.ext)), d / "full" / ("out" + c.ext)}};
  // The other image format of the commands that write either.
  if (c.name == "render" || c.name == "merge") {
    const std::string other = c.ext == ".png" ? ".exr" : ".png";
    runs.push_back({with_output(c, d / "full" / ("out" + other)), d / "full" / ("out" + other)});
  }
  for (const auto& [args, out] : runs) {
    disk.fill_after(out, "old");
    const Result r = drift(args, d);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.log;
    EXPECT_NE(r.log.find(out.filename().string()), std::string::npos) << r.log;
    EXPECT_EQ(slurp(out), "old") << args;
    EXPECT_TRUE(hidden_files(d / "full").empty()) << args;
  }
}

INSTANTIATE_TEST_SUITE_P(OutputsCli, EachCommand, ::testing::ValuesIn(kCommandNames), test_name);

// The inputs of a run are refused as its outputs however they are spelled.
TEST(OutputsCli, InputsAreRefusedAsOutputsUnderAnyName) {
  const Inputs in = make_inputs();
  const fs::path d = test_dir();
  const std::string before = slurp(in.tile1);
  fs::create_hard_link(in.tile1, d / "hard.exr");
  const std::string merge = "merge " + in.tile0.string() + " " + in.tile1.string() + " -o ";
  for (const fs::path& out : {in.dir / "." / "t1.exr", d / "hard.exr"}) {
    const Result r = drift(merge + out.string(), d);
    EXPECT_EQ(r.status, 1) << out << ": " << r.log;
    EXPECT_NE(r.log.find("it is the input"), std::string::npos) << r.log;
  }
  EXPECT_EQ(slurp(in.tile1), before);
  // The scene's own rasters are inputs of a render too: an albedo map named
  // like an image the render may write (a DEM cannot be: -o takes .png or .exr
  // only, and would be refused for its extension), spelled another way.
  fs::copy_file(in.png, d / "albedo.png");
  put(d / "scene.toml",
      "[terrain]\nraster = \"" + in.dem.string() + "\"\nalbedo_map = \"albedo.png\"\n");
  const std::string albedo_before = slurp(d / "albedo.png");
  const Result r = drift("render " + (d / "scene.toml").string() + " --size 16x8 --spp 1 -o " +
                             (d / "a.png").string() + " -o " + (d / "." / "albedo.png").string(),
                         d);
  EXPECT_EQ(r.status, 1) << r.log;
  EXPECT_NE(r.log.find("it is the input"), std::string::npos) << r.log;
  EXPECT_NE(r.log.find("albedo.png"), std::string::npos) << r.log;
  EXPECT_TRUE(slurp(d / "albedo.png") == albedo_before) << "the albedo map was replaced";
  EXPECT_FALSE(fs::exists(d / "a.png"));
  // So is a surround raster ("any GDAL raster in metres", EXR included).
  fs::copy_file(in.tile1, d / "around.exr");
  put(d / "surround.toml",
      "[terrain]\nraster = \"" + in.dem.string() + "\"\nsurround = \"around.exr\"\n");
  const Result s = drift("render " + (d / "surround.toml").string() + " --size 16x8 --spp 1 -o " +
                             (d / "around.exr").string(),
                         d);
  EXPECT_EQ(s.status, 1) << s.log;
  EXPECT_NE(s.log.find("it is the input"), std::string::npos) << s.log;
  EXPECT_TRUE(slurp(d / "around.exr") == before) << "the surround raster was replaced";
}

// Files named inside an input are inputs too: the meshes of an objects or track
// file and the DEM of a soil scenario. Each was replaced by an output named
// like it (snow fall --mesh-out, marks -o, soil --surface) before they were
// counted.
TEST(OutputsCli, FilesNamedInInputsAreRefusedAsOutputs) {
  const Inputs in = make_inputs();
  const fs::path d = test_dir();
  fs::copy_file(DRIFT_SOURCE_DIR "/data/objects/ball.obj", d / "ball.obj");
  drift::terrain::Mesh tetra;
  tetra.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  tetra.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  drift::terrain::write_ply(tetra, d / "rock.ply");
  fs::copy_file(in.dem, d / "dem.tif");
  put(d / "objects.toml", "[[objects]]\nmesh = \"rock.ply\"\nposition = [150, -150, 200]\n");
  std::string track = slurp(in.track);
  track.replace(track.find(DRIFT_SOURCE_DIR "/data/objects/ball.obj"),
                std::string(DRIFT_SOURCE_DIR "/data/objects/ball.obj").size(), "ball.obj");
  put(d / "track.toml", track);
  put(d / "soil.toml",  // a ball of soil over a 4 x 4 window of the 10 m DEM
      "[grid]\nsize = [0, 0, 12]\n[terrain]\ndem = \"dem.tif\"\nwindow = [0, 0, 4, 4]\n"
      "[simulation]\nsteps = 1\n[[soil_body]]\n[[soil_body.primitive]]\nshape = \"sphere\"\n"
      "center = [20, 20, 150]\nradius = 15\n");
  // A scene's meshes, by [[objects]] and by its [terrain] objects file, are
  // render's inputs: OBJ files named like images, so that -o can name them.
  fs::copy_file(d / "ball.obj", d / "m.exr");
  fs::copy_file(d / "ball.obj", d / "n.png");
  put(d / "objs.toml", "[[objects]]\nmesh = \"n.png\"\nposition = [150, -150, 200]\n");
  put(d / "scene.toml",
      "[terrain]\nraster = \"dem.tif\"\nobjects = \"objs.toml\"\n[sun]\nazimuth = 120\n"
      "elevation = 35\n[[objects]]\nmesh = \"m.exr\"\nposition = [100, -100, 200]\n");
  const std::string before_ply = slurp(d / "rock.ply"), before_obj = slurp(d / "ball.obj"),
                    before_dem = slurp(d / "dem.tif"), before_m = slurp(d / "m.exr"),
                    before_n = slurp(d / "n.png");
  const std::string render = "render " + (d / "scene.toml").string() + " --size 8x4 --spp 1 -o ";
  const std::string runs[] = {"snow fall " + in.dem.string() + " --maps 1 --spread 0 --objects " +
                                  (d / "objects.toml").string() + " --mesh-out " +
                                  (d / "rock.ply").string() + " -o " + (d / "depth.tif").string(),
                              "marks " + in.marks_ground.string() + " --track " +
                                  (d / "track.toml").string() + " -o " + (d / "ball.obj").string(),
                              "soil " + (d / "soil.toml").string() + " -o " +
                                  (d / "soil.ply").string() + " --surface " +
                                  (d / "dem.tif").string(),
                              render + (d / "m.exr").string(), render + (d / "n.png").string()};
  for (const std::string& args : runs) {
    const Result r = drift(args, d);
    EXPECT_EQ(r.status, 1) << args << "\n" << r.log;
    // A scene's mesh named like an image is now refused by the mesh reader
    // itself (read by its extension, docs/meshes.md) before the outputs are
    // checked; either way nothing is written over it.
    const bool refused =
        r.log.find("input") != std::string::npos ||
        (args.rfind("render", 0) == 0 && r.log.find("cannot read mesh") != std::string::npos);
    EXPECT_TRUE(refused) << args << "\n" << r.log;
  }
  EXPECT_EQ(slurp(d / "rock.ply"), before_ply);
  EXPECT_EQ(slurp(d / "ball.obj"), before_obj);
  EXPECT_EQ(slurp(d / "dem.tif"), before_dem);
  EXPECT_EQ(slurp(d / "m.exr"), before_m);
  EXPECT_EQ(slurp(d / "n.png"), before_n);
  EXPECT_FALSE(fs::exists(d / "depth.tif") || fs::exists(d / "soil.ply"));
  EXPECT_TRUE(hidden_files(d).empty());
  // The same soil run with another --surface works: it was refused for the DEM.
  EXPECT_EQ(drift("soil " + (d / "soil.toml").string() + " -o " + (d / "soil.ply").string() +
                      " --surface " + (d / "top.tif").string(),
                  d)
                .status,
            0);
  put(d / "plain.toml", "[terrain]\nraster = \"dem.tif\"\n[sun]\nazimuth = 120\nelevation = 35\n");
  const Result rendered = drift("render " + (d / "plain.toml").string() +
                                    " --size 8x4 --spp 1 -o " + (d / "frame.png").string(),
                                d);
  EXPECT_EQ(rendered.status, 0) << rendered.log;
}

// Commands with several outputs: a path named twice or a bad second output is
// found before any work; a failure while writing the second output leaves the
// first as it was.
TEST(OutputsCli, SeveralOutputsAreAllOrNothing) {
  const Inputs in = make_inputs();
  const fs::path d = test_dir(), a = d / "a.png", b = d / "b.exr";
  put(a, "old a");
  put(b, "old b");
  const std::string render = "render " + in.scene.string() + " --size 16x8 --spp 1 -o ";
  Result r = drift(render + a.string() + " -o " + (d / "no" / "b.exr").string(), d);
  EXPECT_EQ(r.status, 1) << r.log;
  EXPECT_NE(r.log.find("does not exist"), std::string::npos) << r.log;
  r = drift(render + a.string() + " -o " + (d / "." / "a.png").string(), d);
  EXPECT_EQ(r.status, 1) << r.log;
  EXPECT_NE(r.log.find("twice"), std::string::npos) << r.log;
  // The second write fails: its temporary file has become a directory.
  auto sabotage = [&] {
    for (const std::string& t : hidden_files(d)) {
      if (t.find(".b.tmp-") != std::string::npos) {
        fs::remove(t);
        fs::create_directory(t);
      }
    }
  };
  r = drift(render + a.string() + " -o " + b.string(), d, {Stop::write, 2}, 0, sabotage);
  EXPECT_EQ(r.status, 1) << r.log;
  EXPECT_EQ(slurp(a), "old a");
  EXPECT_EQ(slurp(b), "old b");
  for (const std::string& t : hidden_files(d)) fs::remove_all(t);  // the sabotage's directory
  // snow cover's three outputs: the third in a missing folder fails before work.
  r = drift("snow cover " + in.dem.string() + " -o " + a.string() + " --descriptor " + b.string() +
                " --accessibility " + (d / "no" / "c.tif").string(),
            d);
  EXPECT_EQ(r.status, 1) << r.log;
  EXPECT_EQ(slurp(a), "old a");
  EXPECT_TRUE(hidden_files(d).empty());
}

// Every signal whose default action ends the process (SIGINT, SIGTERM and
// SIGHUP, and also SIGQUIT, SIGUSR1, SIGALRM, SIGPIPE, SIGXFSZ, ..., which had
// left temporary files behind) during the computation, as the first output is
// being written and as the second is: exit 128 + signal with one line naming
// it, no temporary file left, the existing outputs untouched.
TEST(OutputsCli, SignalsRemoveTemporaryFilesAndKeepOutputs) {
  const Inputs in = make_inputs();
  const std::string render = "render " + in.scene.string() + " --size 16x8 --spp 1 --threads 2 -o ";
  for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGUSR1, SIGUSR2, SIGALRM, SIGPIPE, SIGXFSZ,
                  SIGXCPU, SIGVTALRM, SIGPROF}) {
    for (int at : {1, 2}) {
      const fs::path d = test_dir(), a = d / "a.png", b = d / "b.exr";
      put(a, "old a");
      put(b, "old b");
      const Result r = drift(render + a.string() + " -o " + b.string(), d, {Stop::write, at}, sig);
      EXPECT_EQ(r.status, 128 + sig) << "signal " << sig << " at write " << at << ": " << r.log;
      EXPECT_NE(r.log.find(std::string("interrupted by SIG") + sigabbrev_np(sig)),
                std::string::npos)
          << r.log;
      EXPECT_NE(r.log.find("existing outputs left as they were"), std::string::npos) << r.log;
      EXPECT_EQ(slurp(a), "old a");
      EXPECT_EQ(slurp(b), "old b");
      EXPECT_TRUE(hidden_files(d).empty()) << "signal " << sig << " at write " << at;
    }
    // During the computation (a dune run, at its third progress report), with
    // snapshots already written.
    const fs::path d = test_dir(), out = d / "dunes.tif";
    put(out, "old");
    const Result r = drift("dunes --size 64 --steps 100 --snapshot-every 4 -o " + out.string(), d,
                           {Stop::progress, 3}, sig);
    EXPECT_EQ(r.status, 128 + sig) << r.log;
    EXPECT_NE(r.log.find("interrupted by SIG"), std::string::npos) << r.log;
    EXPECT_TRUE(fs::exists(d / "dunes_00016.tif")) << "no snapshot before the stop";
    EXPECT_FALSE(fs::exists(d / "dunes_00020.tif")) << "went on past the stop";
    EXPECT_EQ(slurp(out), "old");
    EXPECT_TRUE(hidden_files(d).empty()) << "signal " << sig << " during the computation";
    // The snapshots already in place are complete, and the message says so.
    EXPECT_NE(r.log.find("outputs already moved into place are complete"), std::string::npos)
        << r.log;
  }
}

// A file-size limit (ulimit -f) reached while writing: the write fails (its
// SIGXFSZ stays blocked), the run exits 1 naming the output, and no temporary
// file is left (SIGXFSZ's default action had left .NAME.tmp-* behind).
TEST(OutputsCli, FileSizeLimitLeavesNoTemporaryFile) {
  const Inputs in = make_inputs();
  const fs::path d = test_dir(), out = d / "big.exr";
  put(out, "old");
  const std::string cmd = "ulimit -f 4; timeout 60 " + std::string(DRIFT_EXECUTABLE) + " render " +
                          in.scene.string() + " --size 256x128 --spp 1 -o " + out.string() + " > " +
                          (d / "log.txt").string() + " 2>&1";
  const int raw = std::system(("bash -c '" + cmd + "'").c_str());
  const std::string log = slurp(d / "log.txt");
  ASSERT_TRUE(WIFEXITED(raw)) << log;
  EXPECT_EQ(WEXITSTATUS(raw), 1) << log;
  EXPECT_NE(log.find("big.exr"), std::string::npos) << log;
  EXPECT_EQ(slurp(out), "old");
  EXPECT_TRUE(hidden_files(d).empty());
}

// An output folder removed while the run computes: the error names the folder
// and what happened to it, for every kind of writer (PLY/OBJ, GeoTIFF through
// GDAL, images encoded in memory); it had said "disk full?" (issue 34).
TEST(OutputsCli, AnOutputFolderRemovedDuringTheRunIsNamed) {
  const Inputs in = make_inputs();
  const std::string soil =
      "soil " + std::string(DRIFT_SOURCE_DIR) + "/data/soil/cone.toml --steps 1 -o ";
  const std::string runs[] = {soil + "OUT/a.ply", soil + "OUT/a.obj",
                              "import " + in.dem.string() + " -o OUT/a.tif",
                              "render " + in.scene.string() + " --size 16x8 --spp 1 -o OUT/a.png"};
  for (const std::string& run : runs) {
    const fs::path d = test_dir(), out = d / "out";
    fs::create_directories(out);
    std::string args = run;
    args.replace(args.find("OUT"), 3, out.string());
    const Result r = drift(args, d, {Stop::write, 1}, 0, [&] { fs::remove_all(out); });
    EXPECT_EQ(r.status, 1) << args << "\n" << r.log;
    EXPECT_NE(r.log.find("its folder '" + out.string() + "' was removed during the run"),
              std::string::npos)
        << args << "\n"
        << r.log;
    EXPECT_EQ(r.log.find("disk full"), std::string::npos) << r.log;
  }
}

}  // namespace
