#pragma once

// The bake cache: results of expensive CPU or GPU work (the ray-tracing BVH now; lightmaps, probes and
// prefiltered maps later) stored on disk under a key that hashes everything the result depends on, so a
// later run loads them instead of baking again. Bakers own their byte format; the cache only stores
// bytes, checks that they come back whole and never hands out a partial or damaged file.

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace vitrine {

struct BakeKey {
    std::string kind;  // what was baked ("bvh", "lightmap"): a folder of the cache, [a-z0-9_]+
    uint64_t hash = 0; // of all inputs: the scene's content hash, the baker's format version, its parameters
};

// One file of the cache as `vitrine cache ls` shows it.
struct BakeEntry {
    std::filesystem::path path; // the file
    std::string name;           // relative to the cache's dir(): "<kind>/<hash>.bin"
    std::string kind;           // the folder it is in
    uint64_t bytes = 0;         // the whole file, header included
    std::filesystem::file_time_type modified;
    // Empty for a well-formed entry: the 32-byte header's magic is right, its key is the hash in the file name and
    // its size is the file's (the payload's checksum is not read here; get() checks it). Otherwise what is wrong,
    // e.g. "temporary file of an interrupted write".
    std::string problem;
};

// A stored payload mapped read-only into memory (BakeCache::map): the bytes stay in the page cache instead of
// being copied into a buffer first, which for the museum's 64 MiB of textures was most of a warm start.
class BakeView {
public:
    BakeView() = default;
    BakeView(const BakeView&) = delete;
    BakeView& operator=(const BakeView&) = delete;
    BakeView(BakeView&& o) noexcept;
    BakeView& operator=(BakeView&& o) noexcept;
    ~BakeView();

    std::span<const uint8_t> bytes() const;
    // Whether the payload matches the checksum stored with it (what map() checks before it returns a view;
    // mapUnverified() leaves it to the caller, e.g. to a second thread). Reads every byte; safe to call from another
    // thread while this one reads bytes().
    bool intact() const;

private:
    friend class BakeCache;
    void* mBase = nullptr; // the whole file, header included
    size_t mLength = 0;
    size_t mOffset = 0; // where the payload starts
    uint64_t mChecksum = 0; // stored in the header
    int mVersion = 2;       // of the file's format: which checksum it carries
};

class BakeCache {
public:
    // Results live in root/bake/<kind>/<hash>.bin. root: defaultCacheDir() (core/shader/compiler.hpp) for
    // the renderer, a scratch directory in tests.
    explicit BakeCache(std::filesystem::path root);

    // The bytes stored under key; nullopt when there are none, or the file is unreadable, truncated, of
    // another key or fails its checksum (the caller bakes again and put()s over it).
    std::optional<std::vector<uint8_t>> get(const BakeKey& key) const;
    // The same bytes, checked the same way, mapped rather than read (see BakeView).
    std::optional<BakeView> map(const BakeKey& key) const;
    // The same mapping with the header checked (magic of the current format, key, size) but not the payload's
    // checksum: the caller must check BakeView::intact() before it trusts what it built from the bytes (the museum's
    // 64 MiB of textures are checked on a second thread while the geometry is built). A file of the older format
    // gives nullopt: map() reads and rewrites it.
    std::optional<BakeView> mapUnverified(const BakeKey& key) const;

    // Stores bytes under key, replacing what was there. Atomic: written to a temporary file that is then
    // renamed, so a concurrent reader sees the old file or the new one, never a partial one. Returns false
    // (and leaves no temporary behind) when the cache cannot be written: the result is then just not cached.
    bool put(const BakeKey& key, std::span<const uint8_t> bytes) const;

    // Every file under dir() (entries, damaged entries, leftover temporaries), sorted by name; empty when the
    // folder does not exist.
    std::vector<BakeEntry> list() const;

    std::filesystem::path pathOf(const BakeKey& key) const;
    const std::filesystem::path& dir() const { return mDir; }

private:
    // The file mapped with its header checked (magic, key, size); its format's version in the view's mVersion.
    static std::optional<BakeView> mapFile(const std::filesystem::path& path, uint64_t key);

    std::filesystem::path mDir;
};

} // namespace vitrine
