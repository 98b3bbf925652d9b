// Shots on a real Slurm cluster (issue 38; docs/farm.md): Debian's slurmctld
// and slurmd with munge on this machine, started by scripts/slurm-cluster.sh
// — by ctest's fixture (tests/CMakeLists.txt: HAIRVOX_SLURM_DIR) or, when
// this binary runs alone, by the suite itself. If the cluster cannot start or
// does not answer, every test here FAILS with the reason.
//   - an 8-frame turntable as an array of 4 tasks (2 running at once) lands
//     the local render's pixels, and the dependent sheet job makes the movie;
//   - a task cancelled mid-frame leaves no partial file under any name, and
//     the resubmission renders only the frames it did not finish;
//   - two tasks that start together write one cache without corrupting it.
#include "test_util.h"

#include <hairvox/core/error.h>
#include <hairvox/film/image_file.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <map>
#include <regex>
#include <thread>

namespace hairvox {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;
using test::contains;
using test::quoted;

/// Seconds a job of these tests may take before the test gives up on it.
constexpr double kJobTimeout = 120;

class SlurmFarm : public ::testing::Test {
protected:
    static void SetUpTestSuite() {
        const char* given = std::getenv("HAIRVOX_SLURM_DIR");
        if (given && *given) {
            clusterDir() = given;
        } else { // run alone: a cluster of our own
            char pattern[] = "/tmp/hvx-slurm-test-XXXXXX";
            if (!::mkdtemp(pattern)) {
                problem() = "cannot create a directory for the cluster";
                return;
            }
            clusterDir() = pattern;
            ownCluster() = true;
            const auto r = test::runShell(
                "bash " + quoted(fs::path(HAIRVOX_SOURCE_DIR) / "scripts/slurm-cluster.sh") +
                " start " + quoted(clusterDir()) + " 2>&1");
            if (r.exitCode != 0)
                problem() = "scripts/slurm-cluster.sh start failed:\n" + r.output;
        }
        ::setenv("SLURM_CONF", (clusterDir() / "slurm.conf").c_str(), 1);
    }

    static void TearDownTestSuite() {
        if (ownCluster()) {
            test::runShell("bash " +
                           quoted(fs::path(HAIRVOX_SOURCE_DIR) / "scripts/slurm-cluster.sh") +
                           " stop " + quoted(clusterDir()) + " 2>&1");
            std::error_code ec;
            fs::remove_all(clusterDir(), ec);
        }
    }

    void SetUp() override {
        ASSERT_TRUE(problem().empty()) << "no Slurm cluster: " << problem();
        const auto state = test::runShell("sinfo --noheader --format=%t 2>&1");
        ASSERT_TRUE(state.exitCode == 0 &&
                    (contains(state.output, "idle") || contains(state.output, "mix") ||
                     contains(state.output, "alloc")))
            << "the Slurm cluster in " << clusterDir()
            << " does not answer (sinfo: " << state.output << "); its logs are " << clusterDir()
            << "/*.log";
    }

    static fs::path& clusterDir() {
        static fs::path dir;
        return dir;
    }
    static bool& ownCluster() {
        static bool own = false;
        return own;
    }
    static std::string& problem() {
        static std::string p;
        return p;
    }

    /// hairvox in `dir` (where the tasks run too), stdout and stderr.
    test::CommandResult hairvox(const std::string& args) const {
        return test::runShell("cd " + quoted(dir_.path()) +
                              " && HAIRVOX_CACHE_DIR=" + quoted(dir_ / "tables") + " " +
                              quoted(HAIRVOX_BINARY) + " " + args + " 2>&1");
    }

    /// `hairvox submit` and the job id it printed.
    std::string submit(const fs::path& shot, const std::string& args) const {
        const auto r = hairvox("submit " + quoted(shot) + " " + args);
        EXPECT_EQ(r.exitCode, 0) << r.output;
        std::smatch m;
        if (!std::regex_search(r.output, m, std::regex("submitted job ([0-9]+)"))) {
            ADD_FAILURE() << "no job id in: " << r.output;
            return "";
        }
        return m[1];
    }

    /// Waits until no task of the job is pending or running; the states of
    /// its tasks then (scontrol's JobState of each).
    static std::vector<std::string> waitForJob(const std::string& id) {
        const auto deadline = Clock::now() + std::chrono::duration<double>(kJobTimeout);
        while (Clock::now() < deadline) {
            const auto q = test::runShell("squeue --noheader --jobs=" + id +
                                          " --states=PD,R,CG,CF,S --format=%T 2>&1");
            if (q.exitCode == 0 && q.output.find_first_not_of(" \n") == std::string::npos)
                break;
            std::this_thread::sleep_for(std::chrono::milliseconds(250));
        }
        const auto shown = test::runShell("scontrol show job " + id + " 2>&1").output;
        std::vector<std::string> states;
        const std::regex state("JobState=([A-Z_]+)");
        for (auto it = std::sregex_iterator(shown.begin(), shown.end(), state);
             it != std::sregex_iterator(); ++it)
            states.push_back((*it)[1]);
        if (Clock::now() >= deadline) {
            ADD_FAILURE() << "job " << id << " still not done after " << kJobTimeout << " s:\n"
                          << shown;
            test::runShell("scancel " + id);
        }
        return states;
    }

    /// A turntable shot of `frames` frames at `size`², `strands` strands, its
    /// outputs under out/<name>/ (relative: the tasks run in this directory).
    fs::path writeShot(const std::string& name, int frames, int size, int strands) const {
        nlohmann::json doc = nlohmann::json::parse(R"({
          "groom": { "procedural": { "style": "wavy", "seed": 9 } },
          "fiber": { "density_multiplier": 3 },
          "lights": [ { "name": "key", "type": "directional", "direction": [-0.6, 0.65, -0.45],
                        "intensity": 3 },
                      { "name": "back", "type": "directional", "direction": [0.45, 0.3, 0.85],
                        "intensity": 2 } ],
          "camera": { "position": [-0.3, 0.02, -0.6], "look_at": [0, -0.1, 0], "fov": 45,
                      "orbit": { "degrees_per_frame": 45 } },
          "head": { "center": [0, 0, 0], "radius": 0.1 }
        })");
        doc["frames"] = {{"start", 1}, {"end", frames}};
        doc["groom"]["procedural"]["strands"] = strands;
        doc["camera"]["resolution"] = {size, size};
        doc["output"] = {{"exr", "out/" + name + "/f.####.exr"},
                         {"png", "out/" + name + "/f.####.png"}};
        const fs::path path = dir_ / (name + ".json");
        test::writeText(path, doc.dump(2));
        return path;
    }

    /// The task logs (.out) of a job.
    std::string taskLogs(const std::string& shotName, const std::string& id) const {
        std::string all;
        for (const auto& e : fs::directory_iterator(dir_ / (shotName + ".farm/logs")))
            if (e.path().extension() == ".out" &&
                contains(e.path().filename().string(), shotName + "-" + id + "_"))
                all += test::readBytes(e.path());
        return all;
    }

    /// Files whose name says they are writeFileAtomically()'s temporaries.
    static std::vector<fs::path> temporaries(const fs::path& root) {
        std::vector<fs::path> found;
        for (const auto& e : fs::recursive_directory_iterator(root))
            if (contains(e.path().filename().string(), ".tmp-"))
                found.push_back(e.path());
        return found;
    }

    test::TempDir dir_;
};

/// Counts `part` in `text`.
std::size_t count(const std::string& text, const std::string& part) {
    std::size_t n = 0;
    for (std::size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1))
        ++n;
    return n;
}

TEST_F(SlurmFarm, ATurntableAsFourTasksIsTheLocalRenderPixelForPixel) {
    const fs::path local = writeShot("local", 8, 96, 300);
    const fs::path farm = writeShot("farm", 8, 96, 300);
    const auto start = Clock::now();
    const auto rendered = hairvox("render " + quoted(local) + " --quiet");
    ASSERT_EQ(rendered.exitCode, 0) << rendered.output;
    const double localSeconds = std::chrono::duration<double>(Clock::now() - start).count();

    const auto submitted = Clock::now();
    const std::string id = submit(farm, "--per-task 2 --cpus 1 --max-running 2 --sheet");
    ASSERT_FALSE(id.empty());
    const std::vector<std::string> states = waitForJob(id);
    const double farmSeconds = std::chrono::duration<double>(Clock::now() - submitted).count();
    EXPECT_EQ(states, std::vector<std::string>(4, "COMPLETED")) << taskLogs("farm", id);
    const std::string logs = taskLogs("farm", id);
    EXPECT_EQ(count(logs, "2 of 2 frames rendered"), 4u) << logs;
    // Two tasks at a time (--max-running 2): the second pair reads what the first cached.
    EXPECT_GE(count(logs, " read,"), 1u) << "no task read what another cached:\n" << logs;

    for (int f = 1; f <= 8; ++f) {
        const std::string name = strCat("f.000", f);
        SCOPED_TRACE(name);
        const ExrImage a = readExr(dir_ / "out/local" / (name + ".exr"));
        const ExrImage b = readExr(dir_ / "out/farm" / (name + ".exr"));
        ASSERT_EQ(a.channels.size(), b.channels.size());
        EXPECT_GT(a.channels.size(), 20u);
        for (const auto& [channel, values] : a.channels)
            EXPECT_TRUE(b.channels.at(channel) == values) << channel << " differs";
        EXPECT_EQ(a.attributes.at("hairvox:frameHash"), b.attributes.at("hairvox:frameHash"));
        EXPECT_TRUE(test::readBytes(dir_ / "out/local" / (name + ".png")) ==
                    test::readBytes(dir_ / "out/farm" / (name + ".png")));
    }
    // The sheet job ran after the tasks.
    const auto status = hairvox("status " + quoted(farm));
    EXPECT_TRUE(contains(status.output, "8 done, 0 missing, 0 stale")) << status.output;
    const auto deadline = Clock::now() + std::chrono::seconds(60);
    while (!fs::exists(dir_ / "out/farm/farm.sheet.png") && Clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(250));
    EXPECT_TRUE(fs::exists(dir_ / "out/farm/farm.mp4"));
    EXPECT_TRUE(fs::exists(dir_ / "out/farm/farm.sheet.png"));
    std::printf("[ farm     ] 8 frames of 96x96: locally in one process %.2f s; through Slurm "
                "(4 tasks of 2 frames, 1 CPU each, on a 2-CPU node) %.2f s from submit to done\n",
                localSeconds, farmSeconds);
}

TEST_F(SlurmFarm, ACancelledTaskLeavesNoPartialFileAndTheResubmissionRendersOnlyItsFrames) {
    const fs::path shot = writeShot("cancel", 6, 160, 2500);
    const std::string id = submit(shot, "--per-task 6 --cpus 1");
    ASSERT_FALSE(id.empty());
    // Cancelled while it renders frame 2: once frame 1 is written.
    const auto deadline = Clock::now() + std::chrono::duration<double>(kJobTimeout);
    while (!fs::exists(dir_ / "out/cancel/f.0001.exr") && Clock::now() < deadline)
        std::this_thread::sleep_for(std::chrono::milliseconds(20));
    ASSERT_TRUE(fs::exists(dir_ / "out/cancel/f.0001.exr")) << taskLogs("cancel", id);
    ASSERT_EQ(test::runShell("scancel " + id).exitCode, 0);
    const std::vector<std::string> states = waitForJob(id);
    ASSERT_EQ(states, std::vector<std::string>{"CANCELLED"}) << taskLogs("cancel", id);

    // What is there is whole: done frames, the others missing, no temporary.
    const auto before = nlohmann::json::parse(hairvox("status " + quoted(shot) + " --json").output);
    const std::string done = before["done"], missing = before["missing"];
    EXPECT_EQ(before["stale"], "") << before.dump(2);
    EXPECT_EQ(before["blocked"], "");
    ASSERT_FALSE(done.empty());
    ASSERT_FALSE(missing.empty()) << "the task finished before it was cancelled";
    EXPECT_TRUE(temporaries(dir_ / "out").empty()) << temporaries(dir_ / "out").front();
    for (const auto& e : fs::directory_iterator(dir_ / "out/cancel")) {
        if (e.path().extension() == ".exr") {
            EXPECT_TRUE(readExrInfo(e.path()).complete) << e.path();
        }
    }
    std::map<fs::path, fs::file_time_type> written;
    for (const auto& e : fs::directory_iterator(dir_ / "out/cancel"))
        written[e.path()] = e.last_write_time();

    // The resubmission: only the frames not done.
    const auto again = hairvox("submit " + quoted(shot) + " --per-task 6 --cpus 1");
    ASSERT_EQ(again.exitCode, 0) << again.output;
    EXPECT_TRUE(contains(again.output, "frames " + missing + " of ")) << again.output;
    std::smatch m;
    ASSERT_TRUE(std::regex_search(again.output, m, std::regex("submitted job ([0-9]+)")));
    const std::string second = m[1];
    EXPECT_EQ(waitForJob(second), std::vector<std::string>{"COMPLETED"});
    const std::string logs = taskLogs("cancel", second);
    const std::size_t todo =
        nlohmann::json::parse(
            hairvox("status " + quoted(shot) + " --json --frames " + missing).output)["detail"]
            .size();
    EXPECT_TRUE(contains(logs, strCat(todo, " of ", todo, " frames rendered"))) << logs;
    const auto after = nlohmann::json::parse(hairvox("status " + quoted(shot) + " --json").output);
    EXPECT_EQ(after["done"], "1-6") << after.dump(2);
    for (const auto& [path, time] : written)
        EXPECT_EQ(fs::last_write_time(path), time) << path << ": a finished frame rendered again";
}

TEST_F(SlurmFarm, TwoTasksWriteOneCacheAtOnceWithoutCorruption) {
    const fs::path shot = writeShot("race", 4, 64, 1500);
    const std::string id = submit(shot, "--per-task 2 --cpus 1");
    ASSERT_FALSE(id.empty());
    EXPECT_EQ(waitForJob(id), std::vector<std::string>(2, "COMPLETED"));
    const std::string logs = taskLogs("race", id);
    // Both tasks started together (one CPU each of the node's two) and each
    // went to the cache for its first frame.
    EXPECT_EQ(count(logs, "frame 1 (1 of 2): rendered"), 1u) << logs;
    EXPECT_EQ(count(logs, "frame 3 (1 of 2): rendered"), 1u) << logs;
    const auto shown = test::runShell("scontrol show job " + id).output;
    std::vector<std::string> starts;
    const std::regex start("StartTime=([0-9T:-]+)");
    for (auto it = std::sregex_iterator(shown.begin(), shown.end(), start);
         it != std::sregex_iterator(); ++it)
        starts.push_back((*it)[1]);
    ASSERT_EQ(starts.size(), 2u) << shown;
    EXPECT_EQ(starts[0], starts[1]) << "the two tasks did not run at the same time";
    EXPECT_TRUE(temporaries(dir_ / "race.farm/cache").empty());

    // Every entry intact: a render from the cache reads them all and writes
    // none, and is the image the tasks made.
    const auto check = hairvox("render " + quoted(shot) + " --frames 2 --force --quiet --cache " +
                               quoted(dir_ / "race.farm/cache"));
    ASSERT_EQ(check.exitCode, 0) << check.output;
    EXPECT_TRUE(contains(check.output, "cache: 3 read, 0 written")) << check.output;
    EXPECT_FALSE(contains(check.output, "corrupt")) << check.output;
    EXPECT_FALSE(contains(check.output, "warning")) << check.output;
}

} // namespace
} // namespace hairvox
