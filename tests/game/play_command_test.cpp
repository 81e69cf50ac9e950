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

#include "drape/game/asset_paths.hpp"
#include "drape/game/world.hpp"
#include "drape/game/video.hpp"
#include "tests/character/test_character_file.hpp"
#include "tests/test_paths.hpp"
#include "tests/shared_assets.hpp"

namespace drape {
namespace {

namespace fs = std::filesystem;

struct PlayRun {
    int status = -1;
    std::string output;  ///< stdout and stderr
};

// Runs `drape ARGS` in `folder` (shell syntax), with the project's assets.
PlayRun drape(const std::string& args, const fs::path& folder = fs::temp_directory_path(), const std::string& env = "") {
    const std::string command = "cd '" + folder.string() + "' && DRAPE_ASSETS='" + test::source_dir().string() + "/assets' " + env +
                                " '" + test::binary_dir().string() + "/drape' " + args + " 2>&1";
    PlayRun run;
    std::FILE* pipe = ::popen(command.c_str(), "r");
    if (pipe == nullptr) return run;
    std::array<char, 4096> buffer{};
    while (std::fgets(buffer.data(), buffer.size(), pipe) != nullptr) run.output += buffer.data();
    const int status = ::pclose(pipe);
    run.status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return run;
}

// Runs `drape play ARGS`.
PlayRun play(const std::string& args, const fs::path& folder = fs::temp_directory_path(), const std::string& env = "") {
    return drape("play " + args, folder, env);
}

std::string read(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

int lines(const std::string& text) { return static_cast<int>(std::count(text.begin(), text.end(), '\n')); }

class PlayCommand : public ::testing::Test {
protected:
    void SetUp() override {
        if (!fs::exists(test::binary_dir() / "drape")) GTEST_SKIP() << "the drape executable is not built";
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
        {"--headless --hud", "drape play: --hud: nothing is rendered (--headless, or no render module) to draw it on\n"},
        {"--headless --character nothing.glb", "drape play: --character: no such file: nothing.glb\n"},
        {"--headless --stats no/such/folder/stats.json", "drape play: --stats: folder no/such/folder does not exist\n"},
        {"--headless --scene nothing.json", "drape play: nothing.json: no such scene file\n"},
        {"--headless --clip Moonwalk",
         "drape play: --clip: " + test::source_dir().string() + "/assets/avatar.glb: no clip named 'Moonwalk' (clips: 'Walk', 'Idle')\n"},
    };
    for (const Case& c : cases) {
        const PlayRun run = play(c.args, m_dir);
        EXPECT_NE(run.status, 0) << c.args;
        EXPECT_EQ(run.output, c.expected) << c.args;
    }
    EXPECT_TRUE(fs::is_empty(m_dir)) << "a failed run left files behind";
}

TEST_F(PlayCommand, CommandLineErrorsAreOneLineWithTheSameExitCodeAsOtherBadInput) {
    struct Case {
        std::string args, expected;
    };
    const std::vector<Case> cases = {
        {"play --frames -3", "drape play: --frames: must be an integer in [1, 10000000], got -3\n"},
        {"play --frames 2.5", "drape play: --frames: must be an integer in [1, 10000000], got 2.5\n"},
        {"play --frames", "drape play: --frames: needs a value\n"},
        {"play --scene ''", "drape play: --scene: must not be empty\n"},
        {"play --frames 3 --frames 4", "drape play: --frames: given 2 times; give it once\n"},
        {"play --garment hat", "drape play: --garment: must be skirt, dress, none or a garment file (FILE[:MESH]); no such file: hat\n"},
        {"play --model fancy", "drape play: --model: must be one of simplified, classic, got \"fancy\"\n"},
        {"play --fps 0", "drape play: --fps: must be a number in [1, 1000], got 0\n"},
        {"play --fps 1e9", "drape play: --fps: must be a number in [1, 1000], got 1e9\n"},
        {"play --threads -1", "drape play: --threads: must be an integer in [0, 1024], got -1\n"},
        {"play --time-scale inf", "drape play: --time-scale: must be a number in [0, 1000], got inf\n"},
        {"play --size 0x0", "drape play: --size: each side must be in [16, 8192] pixels, got 0x0\n"},
        {"play --colour red", "drape play: --colour: unknown option (--help lists the options)\n"},
        {"play scene.json", "drape play: scene.json: unexpected argument (--help lists the options)\n"},
        {"dance", "drape: dance: no such command (commands: play, inspect, make-avatar"},  // + bench when built
        {"inspect", "drape inspect: give a character file (or --garment FILE)\n"},
        {"inspect missing.glb", "drape inspect: missing.glb: no such file\n"},
    };
    for (const Case& c : cases) {
        const PlayRun run = drape(c.args, m_dir);
        EXPECT_EQ(run.status, 1) << c.args;  // the exit code of every bad input
        if (c.args == "dance")
            EXPECT_EQ(run.output.rfind(c.expected, 0), 0u) << run.output;
        else
            EXPECT_EQ(run.output, c.expected) << c.args;
        EXPECT_EQ(lines(run.output), 1) << run.output;
    }
    const PlayRun help = drape("play --help", m_dir);
    EXPECT_EQ(help.status, 0);
    EXPECT_NE(help.output.find("--overwrite"), std::string::npos) << help.output;
    EXPECT_TRUE(fs::is_empty(m_dir)) << "a failed run left files behind";
}

// `drape bench motions --garment-param NAME=VALUE`: a row of the garment parameter table and a
// value in its range (docs/scenes.md), else one line naming the option and the parameter, and
// nothing runs.
TEST_F(PlayCommand, BenchGarmentParametersAreCheckedByName) {
    // The benchmarks are a subcommand only where they are built (not in the sanitizer build).
    if (drape("--help", m_dir).output.find("\n  bench ") == std::string::npos) GTEST_SKIP() << "drape is built without its benchmarks";
    struct Case {
        std::string args, expected;
    };
    const std::vector<Case> cases = {
        {"bench motions --garment-param foo=1",
         "drape bench: --garment-param foo: no garment parameter of that name (drape scene-parameters lists them)\n"},
        {"bench motions --garment-param inertia_linear=2", "drape bench: --garment-param inertia_linear: must be in [0, 1], got '2'\n"},
        {"bench motions --garment-param inertia_max_linear_m_s2=-1",
         "drape bench: --garment-param inertia_max_linear_m_s2: must be in [0, 10000] m/s^2, got '-1'\n"},
        {"bench motions --garment-param warp_lines=2.5",
         "drape bench: --garment-param warp_lines: must be in integer [2, 4096], got '2.5'\n"},
        {"bench motions --garment-param inertia_linear",
         "drape bench: --garment-param 'inertia_linear': give NAME=VALUE (drape scene-parameters lists the names)\n"},
        {"bench quality --garment-param inertia_linear=0.5", "drape bench: --garment-param: only the motions and cut benchmarks take it\n"},
        {"bench motions --start 0.5", "drape bench: --start: only the stability benchmark takes it\n"},
        {"bench table1 --warp-solve lines", "drape bench: --warp-solve: only the motions and stability benchmarks take it\n"},
        {"bench quality --thicken-thin-trunk 0.015", "drape bench: --thicken-thin-trunk: only the motions benchmark takes it\n"},
        {"bench cut --pin-weights skin_surface", "drape bench: --pin-weights: only the motions benchmark takes it\n"},
    };
    for (const Case& c : cases) {
        const PlayRun run = drape(c.args, m_dir);
        EXPECT_EQ(run.status, 1) << c.args;
        EXPECT_EQ(run.output, c.expected) << c.args;
    }
    EXPECT_TRUE(fs::is_empty(m_dir)) << "a refused run left files behind";
}

TEST_F(PlayCommand, ASceneThatFailsWhileBuildingLeavesNoFolderBehind) {
    if (!render_available()) GTEST_SKIP() << "built without the render module (--out is refused up front there)";
    // Read and checked fine, but no collider crosses a waist 10 m up: fails in build_world.
    std::ofstream(m_dir / "tall_waist.json") << R"({"characters": [{"file": ")" << default_avatar_path().string()
                                             << R"("}], "garments": [{"type": "skirt", "ring_height_m": 9.99}]})";
    for (const std::string args : {"--out new/frames", "", "--video clip.mp4"}) {
        const PlayRun run = play("--scene tall_waist.json --frames 2 --size 64x48 " + args, m_dir);
        EXPECT_EQ(run.status, 1) << args;
        EXPECT_NE(run.output.find("garments[0]: skirt: no collider crosses the ring height"), std::string::npos) << run.output;
        EXPECT_EQ(lines(run.output), 1) << run.output;
        std::vector<std::string> left;
        for (const auto& entry : fs::directory_iterator(m_dir))
            if (entry.path().filename() != "tall_waist.json") left.push_back(entry.path().filename().string());
        EXPECT_TRUE(left.empty()) << args << ": left " << left.front();
    }
    // A folder that existed before stays, and so does what it held.
    fs::create_directories(m_dir / "mine");
    std::ofstream(m_dir / "mine" / "notes.txt") << "keep";
    EXPECT_EQ(play("--scene tall_waist.json --frames 2 --size 64x48 --out mine", m_dir).status, 1);
    EXPECT_EQ(read(m_dir / "mine" / "notes.txt"), "keep");
}

TEST_F(PlayCommand, NamedFilesThatExistAreReplacedOnlyWithOverwrite) {
    for (const std::string option : {"--stats", "--trace"}) {
        std::ofstream(m_dir / "mine.json") << "my own notes";
        PlayRun run = play("--headless --frames 2 " + option + " mine.json", m_dir);
        EXPECT_EQ(run.status, 1);
        EXPECT_EQ(run.output, "drape play: " + option + ": mine.json already exists (add --overwrite to replace it)\n");
        EXPECT_EQ(read(m_dir / "mine.json"), "my own notes");
        run = play("--headless --frames 2 --overwrite " + option + " mine.json", m_dir);
        ASSERT_EQ(run.status, 0) << run.output;
        EXPECT_EQ(read(m_dir / "mine.json").front(), '{') << option;
        std::vector<std::string> files;
        for (const auto& entry : fs::directory_iterator(m_dir)) files.push_back(entry.path().filename().string());
        EXPECT_EQ(files, std::vector<std::string>{"mine.json"}) << "no partial file is left";
    }
    const PlayRun same = play("--headless --frames 2 --overwrite --stats a.json --trace ./a.json", m_dir);
    EXPECT_EQ(same.status, 1);
    EXPECT_EQ(same.output, "drape play: --trace: ./a.json is also the --stats file\n");
}

TEST_F(PlayCommand, FrameFoldersAreReplacedOnlyWithOverwrite) {
    if (!render_available()) GTEST_SKIP() << "built without the render module";
    ASSERT_EQ(play("--frames 3 --size 64x48 --out frames", m_dir).status, 0);
    std::ofstream(m_dir / "frames" / "notes.txt") << "keep";
    PlayRun run = play("--frames 2 --size 64x48 --out frames", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_EQ(run.output, "drape play: --out: frames already holds frames (frame_00000.png, ...); add --overwrite to replace them\n");
    EXPECT_TRUE(fs::exists(m_dir / "frames" / "frame_00002.png"));
    // With --overwrite the folder holds this run's frames only; other files stay.
    run = play("--frames 2 --size 64x48 --out frames --overwrite", m_dir);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_TRUE(fs::exists(m_dir / "frames" / "frame_00001.png"));
    EXPECT_FALSE(fs::exists(m_dir / "frames" / "frame_00002.png"));
    EXPECT_EQ(read(m_dir / "frames" / "notes.txt"), "keep");
    // The default output's folder is a file: refused before anything runs.
    std::ofstream(m_dir / "out") << "a file named out";
    run = play("--frames 2 --size 64x48", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_EQ(run.output, "drape play: out: exists and is not a folder (the default output goes there; name one with --video or --out)\n");
    EXPECT_EQ(read(m_dir / "out"), "a file named out");
    if (find_ffmpeg()) {
        std::ofstream(m_dir / "clip.mp4") << "not a video";
        run = play("--frames 2 --size 64x48 --video clip.mp4", m_dir);
        EXPECT_EQ(run.status, 1);
        EXPECT_EQ(read(m_dir / "clip.mp4"), "not a video");
        run = play("--frames 2 --size 64x48 --video clip.mp4 --overwrite", m_dir);
        ASSERT_EQ(run.status, 0) << run.output;
        EXPECT_NE(read(m_dir / "clip.mp4"), "not a video");
        EXPECT_FALSE(fs::exists(m_dir / ".clip.partial.mp4"));
    }
}

TEST_F(PlayCommand, AVideoThatFailsMidRunLeavesNoPartialFileAndKeepsTheOldOne) {
    if (!render_available()) GTEST_SKIP() << "built without the render module";
    // An ffmpeg that dies at once: the first frame written fails.
    fs::create_directories(m_dir / "bin");
    std::ofstream(m_dir / "bin" / "ffmpeg") << "#!/bin/sh\nexit 3\n";
    fs::permissions(m_dir / "bin" / "ffmpeg", fs::perms::owner_all);
    const std::string path = "PATH='" + (m_dir / "bin").string() + ":/usr/bin:/bin'";
    PlayRun run = play("--frames 3 --size 64x48", m_dir, path);  // default output: out/sample.mp4
    EXPECT_EQ(run.status, 1);
    EXPECT_NE(run.output.find("drape play: out/sample.mp4: ffmpeg stopped accepting frames"), std::string::npos) << run.output;
    EXPECT_FALSE(fs::exists(m_dir / "out")) << "the folder this run created is removed again";
    std::ofstream(m_dir / "clip.mp4") << "an older video";
    run = play("--frames 3 --size 64x48 --video clip.mp4 --overwrite", m_dir, path);
    EXPECT_EQ(run.status, 1);
    EXPECT_NE(run.output.find("drape play: --video: clip.mp4: ffmpeg stopped accepting frames"), std::string::npos) << run.output;
    EXPECT_EQ(read(m_dir / "clip.mp4"), "an older video");
    EXPECT_FALSE(fs::exists(m_dir / ".clip.partial.mp4"));
}

TEST_F(PlayCommand, ImportWarningsArePrintedAndTheCharacterPlays) {
    // An unweighted end bone at its parent's joint: accepted, with one warning line.
    test::write_test_character({.end_bone_offset_m = 0}, m_dir / "column.gltf");
    PlayRun run = play("--headless --frames 2 --character column.gltf --garment none", m_dir);
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("drape play: warning: column.gltf: 1 zero-length end bone without skinned vertices, ignored: 'ChildEnd'\n"),
              std::string::npos) << run.output;
    // The same bone with vertices skinned to it is an error naming the option, file and bone.
    test::write_test_character({.child_offset_m = 0}, m_dir / "folded.gltf");
    run = play("--headless --frames 2 --character folded.gltf --garment none", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_EQ(run.output, "drape play: --character: folded.gltf: bone 'Root' has zero length in the rest pose (its child joints sit "
                          "at its own joint) but 24 vertices are skinned to it\n");
}

TEST_F(PlayCommand, MakeAvatarKeepsAnIdenticalFileAndRefusesToReplaceAnother) {
    PlayRun run = drape("make-avatar --out avatar.glb", m_dir);
    ASSERT_EQ(run.status, 0) << run.output;
    const std::string bytes = read(m_dir / "avatar.glb");
    EXPECT_EQ(bytes, read(default_avatar_path())) << "the generator and the committed avatar agree";
    run = drape("make-avatar --out avatar.glb", m_dir);
    EXPECT_EQ(run.status, 0);
    EXPECT_EQ(run.output, "drape make-avatar: avatar.glb is up to date\n");
    std::ofstream(m_dir / "avatar.glb") << "my own character";
    run = drape("make-avatar --out avatar.glb", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_EQ(run.output, "drape make-avatar: --out: avatar.glb already exists (add --overwrite to replace it)\n");
    EXPECT_EQ(read(m_dir / "avatar.glb"), "my own character");
    run = drape("make-avatar --out avatar.glb --overwrite", m_dir);
    ASSERT_EQ(run.status, 0) << run.output;
    EXPECT_EQ(read(m_dir / "avatar.glb"), bytes);
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
    // The table ends with the whole frame's wall-clock time, over every frame played.
    EXPECT_NE(run.output.find("\nwhole frame (wall clock)            5 "), std::string::npos) << run.output;
    std::ifstream in(m_dir / "stats.json");
    const nlohmann::json stats = nlohmann::json::parse(in);
    EXPECT_EQ(stats["frames"], 5);
    EXPECT_EQ(stats["garments"].size(), 1u);
    EXPECT_EQ(stats["garments"][0]["nonfinite"], 0);
    EXPECT_FALSE(stats["systems"].contains("render"));
    EXPECT_TRUE(fs::exists(m_dir / "trace.json"));
    EXPECT_FALSE(fs::exists(m_dir / "out")) << "headless must not write frames";
}

TEST_F(PlayCommand, VersionIsTheProjectVersion) {
    const PlayRun run = drape("--version", m_dir);
    EXPECT_EQ(run.status, 0);
    EXPECT_EQ(run.output, std::string("drape ") + test::version() + "\n");
}

TEST_F(PlayCommand, EveryRunEndsWithAVerdictOnEachGarment) {
    const PlayRun run = play("--headless --frames 30", m_dir);
    ASSERT_EQ(run.status, 0) << run.output;
    const auto at = run.output.find("\nskirt: strain p99 ");
    ASSERT_NE(at, std::string::npos) << run.output;
    const std::string line = run.output.substr(at + 1, run.output.find('\n', at + 1) - at - 1);
    EXPECT_NE(line.find(", max "), std::string::npos) << line;
    EXPECT_NE(line.find(" mm: within the contract"), std::string::npos) << line;
}

TEST_F(PlayCommand, AGarmentOutsideTheContractIsAWarningAndAFailureOnlyWithStrict) {
    // No strain limit to speak of and a stretch modulus a thousand times too weak: the
    // skirt sags far past 20 %.
    std::ofstream(m_dir / "weak.json") << R"({"characters": [{"file": ")" << test::source_dir().string() << R"(/assets/avatar.glb"}],
        "garments": [{"type": "skirt", "stretch_N_m": 2, "strain_limit": 10}]})";
    const PlayRun run = play("--scene weak.json --headless --frames 30", m_dir);
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("drape play: warning: skirt: strain p99 "), std::string::npos) << run.output;
    EXPECT_NE(run.output.find(": outside the contract: "), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("strain max "), std::string::npos) << run.output;

    const PlayRun strict = play("--scene weak.json --headless --frames 30 --strict", m_dir);
    EXPECT_EQ(strict.status, 1) << strict.output;
    EXPECT_NE(strict.output.find("drape play: 1 garment(s) outside the contract (--strict)\n"), std::string::npos) << strict.output;

    const PlayRun kept = play("--headless --frames 30 --strict", m_dir);
    EXPECT_EQ(kept.status, 0) << kept.output;
}

TEST_F(PlayCommand, ATraceSaysHowManyEventsItDroppedAndItsSizeCanBeSet) {
    const PlayRun small = play("--headless --frames 5 --trace small.json --trace-size 16", m_dir);
    ASSERT_EQ(small.status, 0) << small.output;
    EXPECT_NE(small.output.find("trace: small.json, 16 events\n"), std::string::npos) << small.output;
    EXPECT_NE(small.output.find("drape play: warning: --trace: "), std::string::npos) << small.output;
    EXPECT_NE(small.output.find(" events were dropped: the trace keeps the last 16 (--trace-size N keeps more)"), std::string::npos)
        << small.output;
    std::ifstream in(m_dir / "small.json");
    const nlohmann::json trace = nlohmann::json::parse(in);
    EXPECT_EQ(trace["otherData"]["kept_events"], 16);
    EXPECT_GT(trace["otherData"]["dropped_events"].get<int>(), 0);

    const PlayRun full = play("--headless --frames 5 --trace full.json", m_dir);
    ASSERT_EQ(full.status, 0) << full.output;
    EXPECT_EQ(full.output.find("dropped"), std::string::npos) << full.output;

    const PlayRun alone = play("--headless --frames 5 --trace-size 100", m_dir);
    EXPECT_EQ(alone.status, 1);
    EXPECT_EQ(alone.output, "drape play: --trace-size: needs --trace FILE (the trace it sizes)\n");
}

// Garments from files from the command line (docs/garments.md): a built-in skirt written,
// inspected, played; the cut garments written; nothing overwritten.
TEST_F(PlayCommand, GarmentFilesAreWrittenInspectedAndPlayed) {
    PlayRun run = drape("export-garment --out skirt.gltf", m_dir);
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_TRUE(fs::exists(m_dir / "skirt.gltf") && fs::exists(m_dir / "skirt.bin"));
    run = drape("export-garment --out skirt.gltf", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_EQ(run.output, "drape export-garment: --out: skirt.gltf: exists (not overwritten)\n");
    run = drape("inspect --garment skirt.gltf", m_dir);
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("grid: the mesh's own 27 x 31 lattice, closed, 27 particles held (painted)"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("texture: none (drawn in the garment's colour)"), std::string::npos) << run.output;
    run = play("--headless --frames 30 --garment skirt.gltf", m_dir);
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("skirt: strain p99"), std::string::npos) << run.output;
    run = play("--headless --frames 30 --garment skirt.gltf:Belt", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_NE(run.output.find("skirt.gltf: no mesh named 'Belt' (meshes: Skirt)"), std::string::npos) << run.output;
    EXPECT_EQ(lines(run.output), 1) << run.output;

    // Another character: its own clips (the sample's clip name, Walk, means nothing to it).
    const fs::path other = test::shared_assets() / "characters/male_casual/Male_Casual.fbx";
    if (fs::exists(other)) {
        run = drape("export-garment --garment dress --character '" + other.string() + "' --out dress.glb", m_dir);
        EXPECT_EQ(run.status, 0) << run.output;
        run = drape("make-garments --character '" + other.string() + "' --out cut_other", m_dir);
        EXPECT_EQ(run.status, 0) << run.output;
    }

    run = drape("make-garments --out cut", m_dir);
    EXPECT_EQ(run.status, 0) << run.output;
    for (const char* name : {"flared_skirt", "wrap_skirt", "panel_dress", "cape"}) EXPECT_TRUE(fs::exists(m_dir / "cut" / (std::string(name) + ".glb")));
    run = drape("inspect --garment cut/flared_skirt.glb", m_dir);
    EXPECT_EQ(run.status, 0) << run.output;
    EXPECT_NE(run.output.find("texture: base colour 512x512, by the UVs, repeated"), std::string::npos) << run.output;
    const auto written = fs::last_write_time(m_dir / "cut" / "cape.glb");
    run = drape("make-garments --out cut", m_dir);
    EXPECT_EQ(run.status, 1);
    EXPECT_NE(run.output.find("exists (not overwritten)"), std::string::npos) << run.output;
    EXPECT_EQ(fs::last_write_time(m_dir / "cut" / "cape.glb"), written);
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
