// How commands write files (game/output_files.hpp): never over an existing file without
// consent, and through a partial file renamed onto the target.
#include "drape/game/output_files.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

namespace drape {
namespace {

namespace fs = std::filesystem;

class OutputFiles : public ::testing::Test {
protected:
    void SetUp() override {
        m_dir = fs::temp_directory_path() / ("drape_output_files_" + std::to_string(::getpid()) + "_" +
                                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }
    static std::string read(const fs::path& file) {
        std::ifstream in(file, std::ios::binary);
        return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
    }
    fs::path m_dir;
};

TEST_F(OutputFiles, AnExistingFileIsRefusedUnlessOverwriteIsGiven) {
    const fs::path file = m_dir / "stats.json";
    EXPECT_TRUE(check_new_file("--stats", file, false));
    std::ofstream(file) << "mine";
    auto refused = check_new_file("--stats", file, false);
    ASSERT_FALSE(refused);
    EXPECT_EQ(refused.error().message, "--stats: " + file.string() + " already exists (add --overwrite to replace it)");
    EXPECT_TRUE(check_new_file("--stats", file, true));
    // A folder is never a file to replace, with or without consent.
    auto folder = check_new_file("--stats", m_dir, true);
    ASSERT_FALSE(folder);
    EXPECT_EQ(folder.error().message, "--stats: " + m_dir.string() + " is a folder");
}

TEST_F(OutputFiles, PartialFileIsAHiddenSiblingWithTheSameExtension) {
    EXPECT_EQ(partial_path("out/sample.mp4"), fs::path("out/.sample.partial.mp4"));
    EXPECT_EQ(partial_path("stats.json"), fs::path(".stats.partial.json"));
    EXPECT_EQ(partial_path("trace"), fs::path(".trace.partial"));
}

TEST_F(OutputFiles, CommitReplacesTheTargetAndLeavesNoPartialFile) {
    const fs::path file = m_dir / "trace.json", partial = partial_path(file);
    std::ofstream(file) << "old";
    std::ofstream(partial) << "new";
    ASSERT_TRUE(commit_partial(partial, file));
    EXPECT_EQ(read(file), "new");
    EXPECT_FALSE(fs::exists(partial));
    // A rename that cannot happen (the target is a non-empty folder) removes the partial
    // file and names the target.
    fs::create_directories(m_dir / "taken" / "inside");
    std::ofstream(partial) << "new";
    auto failed = commit_partial(partial, m_dir / "taken");
    ASSERT_FALSE(failed);
    EXPECT_EQ(failed.error().message.rfind((m_dir / "taken").string() + ": cannot write: ", 0), 0u) << failed.error().message;
    EXPECT_FALSE(fs::exists(partial));
    EXPECT_TRUE(fs::exists(m_dir / "taken" / "inside"));
}

}  // namespace
}  // namespace drape
