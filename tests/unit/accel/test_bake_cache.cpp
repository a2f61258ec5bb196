// core/bake/cache: what goes in comes out whole, damaged or foreign files are misses, writes are atomic.
#include "core/bake/cache.hpp"

#include "core/base/error.hpp"
#include "core/scene/hash.hpp"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace vitrine {
namespace {

namespace fs = std::filesystem;

class BakeCacheTest : public ::testing::Test {
protected:
    void SetUp() override {
        mRoot = fs::temp_directory_path() / ("vitrine_bake_test_" + std::to_string(::getpid()) + "_" +
                                             ::testing::UnitTest::GetInstance()->current_test_info()->name());
        fs::remove_all(mRoot);
    }
    void TearDown() override { fs::remove_all(mRoot); }
    fs::path mRoot;
};

std::vector<uint8_t> bytes(size_t n, uint8_t seed) {
    std::vector<uint8_t> v(n);
    for (size_t i = 0; i < n; ++i)
        v[i] = static_cast<uint8_t>(seed + i * 31);
    return v;
}

// What BakeCache::map hands out, copied (nullopt on a miss): it must agree with get() in every case below.
std::optional<std::vector<uint8_t>> mapped(const BakeCache& cache, const BakeKey& key) {
    std::optional<BakeView> view = cache.map(key);
    if (!view) return std::nullopt;
    return std::vector<uint8_t>(view->bytes().begin(), view->bytes().end());
}

TEST_F(BakeCacheTest, StoresAndLoadsBytes) {
    BakeCache cache(mRoot);
    const BakeKey key{"bvh", 0x1234abcdull};
    EXPECT_FALSE(cache.get(key));
    ASSERT_TRUE(cache.put(key, bytes(100000, 7)));
    auto back = cache.get(key);
    ASSERT_TRUE(back);
    EXPECT_EQ(*back, bytes(100000, 7));
    EXPECT_EQ(mapped(cache, key), bytes(100000, 7));
    {
        // A view outlives a move and unmaps once.
        std::optional<BakeView> a = cache.map(key);
        ASSERT_TRUE(a);
        BakeView b = std::move(*a);
        EXPECT_TRUE(a->bytes().empty());
        EXPECT_EQ(b.bytes().size(), 100000u);
        EXPECT_EQ(b.bytes()[99999], bytes(100000, 7)[99999]);
    }
    EXPECT_EQ(cache.pathOf(key), mRoot / "bake" / "bvh" / "000000001234abcd.bin");
    // Another cache object on the same directory (a later run) sees it too; empty payloads are fine.
    EXPECT_EQ(*BakeCache(mRoot).get(key), bytes(100000, 7));
    ASSERT_TRUE(cache.put({"bvh", 1}, {}));
    ASSERT_TRUE(cache.get({"bvh", 1}));
    EXPECT_TRUE(cache.get({"bvh", 1})->empty());
    ASSERT_TRUE(mapped(cache, {"bvh", 1}));
    EXPECT_TRUE(mapped(cache, {"bvh", 1})->empty());
    EXPECT_FALSE(mapped(cache, {"bvh", 2}));
}

TEST_F(BakeCacheTest, KeysAndKindsAreSeparate) {
    BakeCache cache(mRoot);
    ASSERT_TRUE(cache.put({"bvh", 1}, bytes(10, 1)));
    ASSERT_TRUE(cache.put({"lightmap", 1}, bytes(10, 2)));
    EXPECT_EQ(*cache.get({"bvh", 1}), bytes(10, 1));
    EXPECT_EQ(*cache.get({"lightmap", 1}), bytes(10, 2));
    EXPECT_FALSE(cache.get({"bvh", 2}));
    EXPECT_THROW(cache.get({"../x", 1}), InternalError);
    EXPECT_THROW(cache.put({"", 1}, bytes(1, 0)), InternalError);
}

TEST_F(BakeCacheTest, ReplacesAtomicallyAndLeavesNoTemporaries) {
    BakeCache cache(mRoot);
    const BakeKey key{"bvh", 42};
    ASSERT_TRUE(cache.put(key, bytes(5000, 1)));
    ASSERT_TRUE(cache.put(key, bytes(300, 2)));
    EXPECT_EQ(*cache.get(key), bytes(300, 2));
    size_t files = 0;
    for (const auto& e : fs::directory_iterator(cache.pathOf(key).parent_path())) {
        EXPECT_EQ(e.path().extension(), ".bin") << e.path();
        ++files;
    }
    EXPECT_EQ(files, 1u);
}

TEST_F(BakeCacheTest, DamagedOrForeignFilesAreMisses) {
    BakeCache cache(mRoot);
    const BakeKey key{"bvh", 99};
    ASSERT_TRUE(cache.put(key, bytes(4096, 3)));
    const fs::path file = cache.pathOf(key);

    // One payload byte flipped: the checksum fails.
    {
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(32 + 1000);
        f.put(static_cast<char>(0x5a));
    }
    EXPECT_FALSE(cache.get(key));
    EXPECT_FALSE(mapped(cache, key));

    // Truncated.
    ASSERT_TRUE(cache.put(key, bytes(4096, 3)));
    fs::resize_file(file, fs::file_size(file) - 1);
    EXPECT_FALSE(cache.get(key));
    EXPECT_FALSE(mapped(cache, key));

    // Another key's file under this key's name.
    ASSERT_TRUE(cache.put({"bvh", 100}, bytes(4096, 3)));
    fs::copy_file(cache.pathOf({"bvh", 100}), file, fs::copy_options::overwrite_existing);
    EXPECT_FALSE(cache.get(key));
    EXPECT_FALSE(mapped(cache, key));

    // Not a cache file at all.
    std::ofstream(file, std::ios::binary | std::ios::trunc) << "hello";
    EXPECT_FALSE(cache.get(key));
    EXPECT_FALSE(mapped(cache, key));
    // And a put repairs it.
    ASSERT_TRUE(cache.put(key, bytes(64, 9)));
    EXPECT_EQ(*cache.get(key), bytes(64, 9));
    EXPECT_EQ(mapped(cache, key), bytes(64, 9));
}

// The checksum covers every byte: a flip in any of its four interleaved lanes' words or in the tail (a size that is
// not a multiple of 32) is a miss.
TEST_F(BakeCacheTest, AFlipInAnyLaneOrTheTailIsAMiss) {
    BakeCache cache(mRoot);
    const BakeKey key{"bvh", 7};
    const std::vector<uint8_t> payload = bytes(32 * 5 + 13, 4);
    for (size_t at : {0, 8, 16, 24, 32 * 3 + 8 * 3 + 7, 32 * 5, 32 * 5 + 12}) {
        ASSERT_TRUE(cache.put(key, payload));
        ASSERT_EQ(*cache.get(key), payload);
        {
            std::fstream f(cache.pathOf(key), std::ios::in | std::ios::out | std::ios::binary);
            f.seekp(static_cast<std::streamoff>(32 + at));
            f.put(static_cast<char>(payload[at] ^ 0x10));
        }
        EXPECT_FALSE(cache.get(key)) << "byte " << at;
        EXPECT_FALSE(mapped(cache, key)) << "byte " << at;
    }
}

// mapUnverified() checks the header only and leaves the payload's checksum to BakeView::intact(), which the caller
// runs (the museum's textures: on a second thread): a flipped payload byte maps but is not intact; a wrong key, a
// truncated file or no file is no view at all; a version-1 file is left to map(), which reads and rewrites it.
TEST_F(BakeCacheTest, UnverifiedMappingsLeaveTheChecksumToIntact) {
    BakeCache cache(mRoot);
    const BakeKey key{"museum_textures", 11};
    const std::vector<uint8_t> payload = bytes(32 * 7 + 5, 9);
    ASSERT_TRUE(cache.put(key, payload));
    {
        std::optional<BakeView> view = cache.mapUnverified(key);
        ASSERT_TRUE(view);
        EXPECT_EQ(std::vector<uint8_t>(view->bytes().begin(), view->bytes().end()), payload);
        EXPECT_TRUE(view->intact());
        std::optional<BakeView> checked = cache.map(key);
        ASSERT_TRUE(checked);
        EXPECT_TRUE(checked->intact());
    }
    {
        std::fstream f(cache.pathOf(key), std::ios::in | std::ios::out | std::ios::binary);
        f.seekp(32 + 100);
        f.put(static_cast<char>(payload[100] ^ 0x01));
    }
    std::optional<BakeView> damaged = cache.mapUnverified(key);
    ASSERT_TRUE(damaged) << "the header is fine: the view is handed out";
    EXPECT_FALSE(damaged->intact());
    EXPECT_FALSE(cache.map(key));
    EXPECT_FALSE(cache.mapUnverified(BakeKey{"museum_textures", 12}));
    ASSERT_TRUE(cache.put(key, payload));
    fs::resize_file(cache.pathOf(key), 32 + payload.size() - 1);
    EXPECT_FALSE(cache.mapUnverified(key));
    // Version 1: not mapped unverified; map() checks it with the old checksum and rewrites it as version 2.
    {
        std::ofstream out(cache.pathOf(key), std::ios::binary | std::ios::trunc);
        scene::Hasher h;
        h.bytes(payload.data(), payload.size());
        const uint64_t header[3] = {key.hash, payload.size(), h.result()};
        out.write("VTBAKE01", 8);
        out.write(reinterpret_cast<const char*>(header), sizeof header);
        out.write(reinterpret_cast<const char*>(payload.data()), static_cast<std::streamsize>(payload.size()));
    }
    EXPECT_FALSE(cache.mapUnverified(key));
    std::optional<BakeView> old = cache.map(key);
    ASSERT_TRUE(old);
    EXPECT_TRUE(old->intact()) << "a version-1 view is checked with its own checksum";
    std::optional<BakeView> rewritten = cache.mapUnverified(key);
    ASSERT_TRUE(rewritten);
    EXPECT_TRUE(rewritten->intact());
}

// Files written before the four-lane checksum (magic VTBAKE01, the payload's scene::Hasher as checksum) are still
// read, so an existing cache stays valid; damaged ones are misses as before.
TEST_F(BakeCacheTest, VersionOneFilesAreStillRead) {
    BakeCache cache(mRoot);
    const BakeKey key{"lightmap", 0xabcdefull};
    const std::vector<uint8_t> payload = bytes(1000, 6);
    auto writeV1 = [&](uint64_t checksum) {
        fs::create_directories(cache.pathOf(key).parent_path());
        std::ofstream out(cache.pathOf(key), std::ios::binary | std::ios::trunc);
        const uint64_t header[3] = {key.hash, payload.size(), checksum};
        out.write("VTBAKE01", 8);
        out.write(reinterpret_cast<const char*>(header), sizeof header);
        out.write(reinterpret_cast<const char*>(payload.data()), static_cast<std::streamsize>(payload.size()));
    };
    scene::Hasher h;
    h.bytes(payload.data(), payload.size());
    auto magicOnDisk = [&] {
        char magic[8] = {};
        std::ifstream(cache.pathOf(key), std::ios::binary).read(magic, 8);
        return std::string(magic, 8);
    };
    writeV1(h.result());
    ASSERT_TRUE(cache.get(key));
    // The first read rewrote the entry in the new version (same name, same payload), so later reads pay the new
    // checksum; a second read gives the same bytes from it.
    EXPECT_EQ(magicOnDisk(), "VTBAKE02");
    EXPECT_EQ(*cache.get(key), payload);
    writeV1(h.result());
    EXPECT_EQ(mapped(cache, key), payload);
    EXPECT_EQ(magicOnDisk(), "VTBAKE02");
    EXPECT_EQ(mapped(cache, key), payload);
    // A damaged version-1 file is a miss, and is left as it is.
    writeV1(h.result() ^ 1);
    EXPECT_FALSE(cache.get(key));
    EXPECT_FALSE(mapped(cache, key));
    EXPECT_EQ(magicOnDisk(), "VTBAKE01");
    // What put() writes now is the new version, under the same name.
    ASSERT_TRUE(cache.put(key, payload));
    EXPECT_EQ(magicOnDisk(), "VTBAKE02");
    EXPECT_EQ(*cache.get(key), payload);
}

TEST_F(BakeCacheTest, UnwritableCacheIsReportedNotThrown) {
    fs::create_directories(mRoot);
    std::ofstream(mRoot / "bake") << "a file where the cache's folder should be";
    BakeCache cache(mRoot);
    EXPECT_FALSE(cache.put({"bvh", 1}, bytes(10, 0)));
    EXPECT_FALSE(cache.get({"bvh", 1}));
}

} // namespace
} // namespace vitrine
