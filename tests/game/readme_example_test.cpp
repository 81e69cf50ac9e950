// README.md's C++ example is the code the consumer test compiles against the installed
// package (tests/consumer/main.cpp, between its "README" markers), and its CMake lines are
// the consumer project's.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <sstream>
#include <string>

#include "tests/test_paths.hpp"

namespace drape {
namespace {

std::string read(const std::string& relative) {
    std::ifstream in(test::source_dir().string() + "/" + relative);
    EXPECT_TRUE(in) << relative << " is missing";
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// The first fenced block of `language` after `heading`, without its fences.
std::string fenced_block(const std::string& text, const std::string& heading, const std::string& language) {
    const std::size_t section = text.find(heading);
    if (section == std::string::npos) return {};
    const std::string fence = "```" + language + "\n";
    const std::size_t from = text.find(fence, section);
    if (from == std::string::npos) return {};
    const std::size_t body = from + fence.size();
    return text.substr(body, text.find("```", body) - body);
}

// The lines between the markers, each without its first `indent` spaces.
std::string between_markers(const std::string& text, const std::string& begin, const std::string& end, std::size_t indent) {
    const std::size_t from = text.find(begin);
    const std::size_t to = text.find(end);
    if (from == std::string::npos || to == std::string::npos) return {};
    std::istringstream lines(text.substr(text.find('\n', from) + 1, text.rfind('\n', to) + 1 - (text.find('\n', from) + 1)));
    std::string out, line;
    while (std::getline(lines, line)) out += (line.size() >= indent ? line.substr(indent) : std::string()) + "\n";
    return out;
}

TEST(ReadmeExample, IsTheCodeTheConsumerTestCompiles) {
    const std::string readme = read("README.md");
    const std::string example = fenced_block(readme, "## Use it in your CMake project", "cpp");
    ASSERT_FALSE(example.empty()) << "README.md has no C++ example under \"Use it in your CMake project\"";
    const std::string consumer = between_markers(read("tests/consumer/main.cpp"), "// --- README: begin", "// --- README: end", 4);
    ASSERT_FALSE(consumer.empty()) << "tests/consumer/main.cpp lacks its README markers";
    EXPECT_EQ(example, consumer) << "README.md's example and tests/consumer/main.cpp differ";
}

TEST(ReadmeExample, ItsCMakeLinesAreTheConsumerProjects) {
    const std::string cmake = fenced_block(read("README.md"), "## Use it in your CMake project", "cmake");
    ASSERT_FALSE(cmake.empty());
    const std::string consumer = read("tests/consumer/CMakeLists.txt");
    std::istringstream lines(cmake);
    for (std::string line; std::getline(lines, line);)
        EXPECT_NE(consumer.find(line + "\n"), std::string::npos) << "tests/consumer/CMakeLists.txt lacks README's line: " << line;
}

}  // namespace
}  // namespace drape
