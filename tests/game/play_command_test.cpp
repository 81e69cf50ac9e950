// `drape play` as a user runs it: bad values give one line naming the option and a
// non-zero exit; outputs land where asked; default outputs never overwrite a file.
#include <gtest/gtest.h>

#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <sys/wait.h>

#include <nlohmann/json.hpp>

#include "game/scene.hpp"
#include "game/video.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

struct PlayRun {
    int status = -1;
    std::string output;  ///< stdout and stderr
};

// Runs `drape play ARGS` in `folder` (shell syntax), with the project's assets.
PlayRun play(const std::string& args, const fs::path& folder = fs::temp_directory_path(), const std::string& env = "") {
    const std::string command = "cd '" + folder.string() + "' && DRAPE_ASSETS='" + std::string(DRAPE_SOURCE_DIR) + "/assets' " + env +
                                " '" + std::string(DRAPE_BINARY_DIR) + "/drape' play " + args + " 2>&1";
    PlayRun run;
    std::FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return run;
    std::array<char, 4096> buffer{};
    while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) run.output += buffer.data();
    const int status = ::pclose(pipe);
    run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

int lines(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

class PlayCommand : public ::testing::Test {
protected:
    void SetUp() override {
        if (!fs::exists(fs::path(DRAPE_BINARY_DIR) / "drape")) GTEST_SKIP() << "the drape executable is not built";
        m_dir = fs::temp_directory_path() / ("drape_play_test_" + std::to_string(::getpid()) + "_" +
                                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override {
        if (!m_dir.empty()) fs::remove_all(m_dir);
    }
    fs::path m_dir;
};

TEST_F(PlayCommand, BadValuesGiveOneLineNamingTheOption) {
    struct Case {
        std::string args, expected;
    };
    const std::vector<Case> cases = {
        {"--size 12x5 --headless", "drape play: --size: each side must be in [16, 8192] pixels, got 12x5\n"},
        {"--size big", "drape play: --size: must be WIDTHxHEIGHT in pixels, e.g. 1280x720, got \"big\"\n"},
        {"--headless --fps nan", "drape play: --fps: must be a number in [1, 1000], got nan\n"},
        {"--headless --time-scale nan", "drape play: --time-scale: must be a number in [0, 1000], got nan\n"},
        {"--headless --out frames", "drape play: --headless: cannot be combined with --out (nothing is rendered)\n"},
        {"--headless --window", "drape play: --headless: cannot be combined with --window (nothing is rendered)\n"},
        {"--headless --character nothing.glb", "drape play: --character: no such file: nothing.glb\n"},
        {"--headless --stats no/such/folder/stats.json", "drape play: --stats: folder no/such/folder does not exist\n"},
        {"--headless --scene nothing.json", "drape play: nothing.json: no such scene file\n"},
        {"--headless --clip Moonwalk",
         "drape play: --clip: " + std::string(DRAPE_SOURCE_DIR) + "/assets/avatar.glb: no clip named 'Moonwalk' (clips: 'Walk', 'Idle')\n"},
    };
    for (const Case& c : cases) {
        const PlayRun run = play(c.args, m_dir);
        EXPECT_NE(run.status, 0) << c.args;
        EXPECT_EQ(run.output, c.expected) << c.args;
    }
    // CLI11's own checks: the option and the reason on the first line.
    for (const std::string args : {"--frames 0", "--garment shirt", "--model fancy", "--threads -1", "--time-scale -2"}) {
        const PlayRun run = play(args, m_dir);
        EXPECT_NE(run.status, 0) << args;
        EXPECT_EQ(run.output.rfind(args.substr(0, args.find(' ')) + ": ", 0), 0u) << run.output;
        EXPECT_LE(lines(run.output), 2) << run.output;
    }
    EXPECT_TRUE(fs::is_empty(m_dir)) << "a failed run left files behind";
}

TEST_F(PlayCommand, SceneFileErrorsCarryLineAndColumn) {
    std::ofstream(m_dir / "bad.json") << "{\n  \"characters\": [{\"file\": \"x.glb\", \"speed\": -1}]\n}";
    const PlayRun run = play("--scene bad.json --headless", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_EQ(run.output, "drape play: bad.json:2:27: characters[0].file: no such file: x.glb\n");
}

TEST_F(PlayCommand, HeadlessRunWritesStatsAndTrace) {
    const PlayRun run = play("--headless --frames 5 --stats stats.json --trace trace.json", m_dir);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("Frame budget"), std::string::npos) << run.output;
    std::ifstream in(m_dir / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(in);
    EXPECT_EQ(stats["frames"], 5);
    EXPECT_EQ(stats["garments"].size(), 1u);
    EXPECT_EQ(stats["garments"][0]["nonfinite"], 0);
    EXPECT_FALSE(stats["systems"].contains("render"));
    EXPECT_TRUE(fs::exists(m_dir / "trace.json"));
    EXPECT_FALSE(fs::exists(m_dir / "out")) << "headless must not write frames";
}

TEST_F(PlayCommand, VideoWithoutFfmpegIsAClearError) {
    const PlayRun run = play("--video v.mp4 --frames 2", m_dir, "PATH=/nonexistent");
    EXPECT_EQ(run.status, 1);
    EXPECT_EQ(run.output, render_available()
                              ? "drape play: --video: ffmpeg is not installed (apt-get install ffmpeg); --out DIR writes PNG frames instead\n"
                              : "drape play: --video: this build has no render module (configured with -DDRAPE_RENDER=OFF)\n");
    EXPECT_FALSE(fs::exists(m_dir / "v.mp4"));
}

TEST_F(PlayCommand, FramesGoWhereAskedAndDefaultsNeverOverwrite) {
    if (!render_available()) GTEST_SKIP() << "built without the render module";
    PlayRun run = play("--frames 2 --size 64x48 --out frames", m_dir);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_TRUE(fs::exists(m_dir / "frames" / "frame_00000.png"));
    EXPECT_TRUE(fs::exists(m_dir / "frames" / "frame_00001.png"));
    EXPECT_FALSE(fs::exists(m_dir / "frames" / "frame_00002.png"));

    // No output named: a new file under out/ each time.
    const bool video = find_ffmpeg().has_value();
    for (int i = 0; i < 2; ++i) {
        run = play("--frames 2 --size 64x48", m_dir);
        ASSERT_EQ(run.status, 0) << run.output;
    }
    if (video) {
        EXPECT_GT(fs::file_size(m_dir / "out" / "sample.mp4"), 0u);
        EXPECT_GT(fs::file_size(m_dir / "out" / "sample-2.mp4"), 0u);
    } else {
        EXPECT_TRUE(fs::exists(m_dir / "out" / "sample_frames" / "frame_00001.png"));
        EXPECT_TRUE(fs::exists(m_dir / "out" / "sample_frames-2" / "frame_00001.png"));
    }
}

}  // namespace
}  // namespace drape
