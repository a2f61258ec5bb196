#include "core/base/atomic_file.hpp"

#include "core/base/error.hpp"

#include <fcntl.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <fstream>

namespace vitrine {

namespace fs = std::filesystem;

namespace {

fs::path temporaryFor(const fs::path& path) {
    static std::atomic<unsigned> counter{0};
    std::string name = "." + path.filename().string() + ".tmp-" + std::to_string(::getpid()) + "-" +
                       std::to_string(counter.fetch_add(1));
    return path.parent_path() / name;
}

std::string replaceAll(std::string text, const std::string& from, const std::string& to) {
    if (from.empty()) return text;
    for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at + to.size()))
        text.replace(at, from.size(), to);
    return text;
}

void killHalfwayForTests(const fs::path& path, const fs::path& temporary) {
    const char* name = std::getenv("VITRINE_TEST_KILL_DURING_WRITE");
    if (!name || path.filename() != name) return;
    std::error_code ec;
    fs::resize_file(temporary, fs::file_size(temporary, ec) / 2, ec);
    ::raise(SIGKILL);
}

// Flushes the temporary file's data to the disk, so a power cut after the rename cannot leave an empty file.
bool syncFile(const fs::path& file) {
    int fd = ::open(file.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return false;
    bool ok = ::fsync(fd) == 0;
    ::close(fd);
    return ok;
}

} // namespace

void writeFileAtomically(const fs::path& path, const std::function<void(const fs::path& temporary)>& write) {
    const fs::path directory = path.parent_path();
    std::error_code ec;
    if (!directory.empty() && !fs::is_directory(directory, ec))
        throw UserError(path.string() + ": cannot open for writing: directory '" + directory.string() +
                        "' does not exist");
    const fs::path temporary = temporaryFor(path);
    try {
        write(temporary);
    } catch (const UserError& e) {
        fs::remove(temporary, ec);
        throw UserError(replaceAll(e.what(), temporary.string(), path.string()));
    } catch (const InternalError& e) {
        fs::remove(temporary, ec);
        throw InternalError(replaceAll(e.what(), temporary.string(), path.string()));
    } catch (...) {
        fs::remove(temporary, ec);
        throw;
    }
    killHalfwayForTests(path, temporary);
    if (!syncFile(temporary)) {
        std::string reason = std::strerror(errno);
        fs::remove(temporary, ec);
        throw UserError(path.string() + ": cannot write (" + reason + ")");
    }
    fs::rename(temporary, path, ec);
    if (ec) {
        std::string reason = ec.message();
        fs::remove(temporary, ec);
        throw UserError(path.string() + ": cannot replace the file (" + reason + ")");
    }
}

void writeFileAtomically(const fs::path& path, std::string_view bytes) {
    writeFileAtomically(path, [&](const fs::path& temporary) {
        std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
        if (!out) throw UserError(path.string() + ": cannot open for writing (" + std::strerror(errno) + ")");
        out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
        out.close();
        if (!out) throw UserError(path.string() + ": cannot write (" + std::strerror(errno) + ")");
    });
}

} // namespace vitrine
