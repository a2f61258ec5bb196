#include "core/bake/cache.hpp"

#include "core/base/error.hpp"
#include "core/scene/hash.hpp"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <utility>

namespace vitrine {

namespace fs = std::filesystem;

namespace {

// VTBAKE02 files carry checksum() below; VTBAKE01 files (written before 2026-12-05) carry checksumV1() and are still
// read, so an existing cache stays valid. put() writes VTBAKE02, and map() rewrites a valid VTBAKE01 file as VTBAKE02
// once, so an entry that is only ever read (the museum's textures) stops paying the old checksum.
constexpr char kMagic[8] = {'V', 'T', 'B', 'A', 'K', 'E', '0', '2'};
constexpr char kMagicV1[8] = {'V', 'T', 'B', 'A', 'K', 'E', '0', '1'};

// The file: this header, then the payload.
struct Header {
    char magic[8];
    uint64_t key;
    uint64_t size;
    uint64_t checksum;
};
static_assert(sizeof(Header) == 32);

// The version-1 checksum: one scene::Hasher over the payload, a single chain of dependent multiplies (about 37 ms
// for the museum's 64 MiB of textures, a sixth of a warm start's scene build).
uint64_t checksumV1(std::span<const uint8_t> bytes) {
    scene::Hasher h;
    h.bytes(bytes.data(), bytes.size());
    return h.result();
}

// The payload's checksum: four independent scene::Hasher lanes over interleaved 8-byte words (the CPU overlaps
// their multiplies), the tail and the size in a fifth, the lanes' results hashed together.
uint64_t checksum(std::span<const uint8_t> bytes) {
    scene::Hasher lanes[4];
    const size_t blocks = bytes.size() / 32;
    const uint8_t* p = bytes.data();
    for (size_t i = 0; i < blocks; ++i, p += 32)
        for (int l = 0; l < 4; ++l) {
            uint64_t w;
            std::memcpy(&w, p + 8 * l, 8);
            lanes[l].word(w);
        }
    scene::Hasher h;
    h.bytes(p, bytes.size() - blocks * 32);
    h.value(static_cast<uint64_t>(bytes.size()));
    for (const scene::Hasher& lane : lanes) h.value(lane.result());
    return h.result();
}

void checkKind(const std::string& kind) {
    bool ok = !kind.empty();
    for (char c : kind)
        ok = ok && ((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_');
    if (!ok) throw InternalError("bake cache: kind '" + kind + "' must be made of [a-z0-9_]");
}

} // namespace

BakeCache::BakeCache(fs::path root) : mDir(std::move(root) / "bake") {}

fs::path BakeCache::pathOf(const BakeKey& key) const {
    checkKind(key.kind);
    char name[32];
    std::snprintf(name, sizeof name, "%016llx.bin", static_cast<unsigned long long>(key.hash));
    return mDir / key.kind / name;
}

std::optional<std::vector<uint8_t>> BakeCache::get(const BakeKey& key) const {
    std::optional<BakeView> view = map(key);
    if (!view) return std::nullopt;
    return std::vector<uint8_t>(view->bytes().begin(), view->bytes().end());
}

BakeView::BakeView(BakeView&& o) noexcept { *this = std::move(o); }

BakeView& BakeView::operator=(BakeView&& o) noexcept {
    if (this != &o) {
        if (mBase) ::munmap(mBase, mLength);
        mBase = std::exchange(o.mBase, nullptr);
        mLength = std::exchange(o.mLength, 0);
        mOffset = std::exchange(o.mOffset, 0);
        mChecksum = std::exchange(o.mChecksum, 0);
        mVersion = std::exchange(o.mVersion, 2);
    }
    return *this;
}

BakeView::~BakeView() {
    if (mBase) ::munmap(mBase, mLength);
}

std::span<const uint8_t> BakeView::bytes() const {
    if (!mBase) return {};
    return {static_cast<const uint8_t*>(mBase) + mOffset, mLength - mOffset};
}

bool BakeView::intact() const {
    return mBase && (mVersion == 1 ? checksumV1(bytes()) : checksum(bytes())) == mChecksum;
}

// The file mapped, its header checked (magic, key, size); the view's mVersion says which checksum it carries.
std::optional<BakeView> BakeCache::mapFile(const fs::path& path, uint64_t key) {
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0) return std::nullopt;
    struct stat st {};
    void* base = MAP_FAILED;
    if (::fstat(fd, &st) == 0 && static_cast<uint64_t>(st.st_size) >= sizeof(Header))
        // MAP_POPULATE: one call maps every page of the file (already in the page cache on a warm start) instead
        // of a page fault per 4 KiB while the payload is checked and read.
        base = ::mmap(nullptr, static_cast<size_t>(st.st_size), PROT_READ, MAP_PRIVATE | MAP_POPULATE, fd, 0);
    ::close(fd);
    if (base == MAP_FAILED) return std::nullopt;
    Header h{};
    std::memcpy(&h, base, sizeof h);
    const size_t length = static_cast<size_t>(st.st_size);
    BakeView view; // unmaps when dropped
    view.mBase = base;
    view.mLength = length;
    view.mOffset = sizeof(Header);
    view.mChecksum = h.checksum;
    view.mVersion = std::memcmp(h.magic, kMagic, sizeof kMagic) == 0       ? 2
                    : std::memcmp(h.magic, kMagicV1, sizeof kMagicV1) == 0 ? 1
                                                                           : 0;
    if (view.mVersion == 0 || h.key != key || sizeof(Header) + h.size != length) return std::nullopt;
    return view;
}

std::optional<BakeView> BakeCache::map(const BakeKey& key) const {
    std::optional<BakeView> view = mapFile(pathOf(key), key.hash);
    if (!view || !view->intact()) return std::nullopt;
    // The rewrite replaces the file by rename: this view keeps mapping the old one. A failed rewrite (a read-only
    // cache) only means the next read checks the old checksum again.
    if (view->mVersion == 1) put(key, view->bytes());
    return view;
}

std::optional<BakeView> BakeCache::mapUnverified(const BakeKey& key) const {
    std::optional<BakeView> view = mapFile(pathOf(key), key.hash);
    if (!view || view->mVersion != 2) return std::nullopt;
    return view;
}

bool BakeCache::put(const BakeKey& key, std::span<const uint8_t> bytes) const {
    const fs::path path = pathOf(key);
    std::error_code ec;
    fs::create_directories(path.parent_path(), ec);
    // Unique per process and call, so concurrent writers of the same key never share a temporary.
    static std::atomic<uint32_t> sCounter{0};
    const fs::path tmp = path.string() + ".tmp" + std::to_string(::getpid()) + "." + std::to_string(sCounter++);
    Header h{};
    std::memcpy(h.magic, kMagic, sizeof kMagic);
    h.key = key.hash;
    h.size = bytes.size();
    h.checksum = checksum(bytes);
    bool ok;
    {
        std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
        out.write(reinterpret_cast<const char*>(&h), sizeof h);
        out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
        out.close();
        ok = static_cast<bool>(out);
    }
    if (ok) fs::rename(tmp, path, ec);
    if (!ok || ec) {
        fs::remove(tmp, ec);
        return false;
    }
    return true;
}

std::vector<BakeEntry> BakeCache::list() const {
    std::vector<BakeEntry> entries;
    std::error_code ec;
    if (!fs::is_directory(mDir, ec)) return entries;
    for (auto it = fs::recursive_directory_iterator(mDir, ec); !ec && it != fs::recursive_directory_iterator();
         it.increment(ec)) {
        std::error_code fileEc;
        if (!it->is_regular_file(fileEc)) continue;
        BakeEntry e;
        e.path = it->path();
        e.name = fs::relative(e.path, mDir, fileEc).generic_string();
        const fs::path relative(e.name);
        e.kind = std::distance(relative.begin(), relative.end()) > 1 ? relative.begin()->string() : std::string();
        e.bytes = it->file_size(fileEc);
        e.modified = it->last_write_time(fileEc);
        const std::string file = e.path.filename().string();
        if (file.find(".tmp") != std::string::npos) {
            e.problem = "temporary file of an interrupted write";
        } else if (e.kind.empty()) {
            e.problem = "not in a kind folder";
        } else {
            Header h{};
            std::ifstream in(e.path, std::ios::binary);
            char* end = nullptr;
            const unsigned long long hash = std::strtoull(e.path.stem().string().c_str(), &end, 16);
            if (!in.read(reinterpret_cast<char*>(&h), sizeof h))
                e.problem = "shorter than the 32-byte header";
            else if (std::memcmp(h.magic, kMagic, sizeof kMagic) != 0 && std::memcmp(h.magic, kMagicV1, sizeof kMagicV1) != 0)
                e.problem = "not a bake cache file (no VTBAKE02 or VTBAKE01 magic)";
            else if (e.path.extension() != ".bin" || *end != '\0' || h.key != hash)
                e.problem = "the header's key is not the file name's";
            else if (h.size != e.bytes - sizeof(Header))
                e.problem = "truncated (the header says " + std::to_string(h.size) + " payload bytes)";
        }
        entries.push_back(std::move(e));
    }
    std::sort(entries.begin(), entries.end(), [](const BakeEntry& a, const BakeEntry& b) { return a.name < b.name; });
    return entries;
}

} // namespace vitrine
