#pragma once
// A test fixture with a fresh directory per test, removed afterwards, and files written into it.

#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace cellrt::test {

class TempDirTest : public ::testing::Test {
protected:
    // `prefix` names the directory (under the system's temporary folder) after the test file.
    explicit TempDirTest(std::string prefix) : prefix_(std::move(prefix)) {}

    void SetUp() override {
        static std::atomic<int> counter{0};
        dir_ = std::filesystem::temp_directory_path() /
               (prefix_ + "_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::remove_all(dir_);
        std::filesystem::create_directories(dir_);
    }
    void TearDown() override { std::filesystem::remove_all(dir_); }

    // `bytes` as the file `name` in the directory; returns its path.
    std::string write(const std::string& name, const std::string& bytes) const {
        const std::string path = (dir_ / name).string();
        std::ofstream(path, std::ios::binary) << bytes;
        return path;
    }

    std::string prefix_;
    std::filesystem::path dir_;
};

}  // namespace cellrt::test
