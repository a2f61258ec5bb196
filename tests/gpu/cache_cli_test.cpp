// `vitrine cache ls` and `vitrine cache rm` on a bake cache filled here through core/bake's BakeCache (the writer the
// bakers use), in a scratch VITRINE_CACHE_DIR: what ls lists (kind, size, total, damaged files), what rm removes and
// what it refuses (names outside the cache folder, also through a symbolic link), with the files checked on disk.
#include "core/bake/cache.hpp"
#include "tests/gpu/cli.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <vector>

namespace vitrine::test {
namespace {

namespace fs = std::filesystem;

TEST(CacheCli, ListsAndRemovesEntriesAndNothingOutside) {
    const fs::path root = freshDir("cache_cli");
    const fs::path cacheDir = root / "cache";
    const BakeCache cache(cacheDir);
    ASSERT_TRUE(cache.put({"bvh", 0x1234}, std::vector<uint8_t>(1000, 7)));
    ASSERT_TRUE(cache.put({"bvh", 0xabcdef}, std::vector<uint8_t>(10, 1)));
    ASSERT_TRUE(cache.put({"reference", 0x42}, std::vector<uint8_t>(3 * 1024 * 1024, 2)));
    std::ofstream(cacheDir / "bake" / "bvh" / "00000000000000ff.bin") << "garbage, not a cache file but longer than its header";
    // Outside the cache: must survive every rm.
    std::ofstream(root / "precious.txt") << "mine";
    fs::create_directories(root / "elsewhere");
    std::ofstream(root / "elsewhere" / "0000000000000001.bin") << "mine too";
    fs::create_directory_symlink(root / "elsewhere", cacheDir / "bake" / "link");
    const std::string env = "VITRINE_CACHE_DIR=" + quote(cacheDir.string());

    const CliResult ls = vitrine("cache ls", env);
    ASSERT_EQ(ls.status, 0) << ls.output;
    std::printf("%s", ls.output.c_str());
    EXPECT_NE(ls.output.find("bvh/0000000000001234.bin"), std::string::npos) << ls.output;
    EXPECT_NE(ls.output.find("reference/0000000000000042.bin"), std::string::npos) << ls.output;
    EXPECT_NE(ls.output.find("1.0 KiB"), std::string::npos) << ls.output; // 32-byte header + 1000
    EXPECT_NE(ls.output.find("3.0 MiB"), std::string::npos) << ls.output;
    EXPECT_NE(ls.output.find("42 B"), std::string::npos) << ls.output; // header + 10
    EXPECT_NE(ls.output.find("no VTBAKE02 or VTBAKE01 magic"), std::string::npos) << ls.output;
    // 4 files: 1032 + 42 + 3 MiB + 32 bytes and the garbage; the symlinked folder is not followed.
    EXPECT_NE(ls.output.find("4 entries, 3.0 MiB in all"), std::string::npos) << ls.output;
    EXPECT_EQ(ls.output.find("0000000000000001.bin"), std::string::npos) << ls.output;

    // Refused, nothing removed: outside by "..", absolute, through the link, or not there.
    for (const std::string& name :
         {std::string("../../precious.txt"), (root / "precious.txt").string(), std::string("link/0000000000000001.bin"),
          std::string("bvh/0000000000009999.bin")}) {
        const CliResult r = vitrine("cache rm " + quote(name), env);
        EXPECT_EQ(r.status, 1) << name << ": " << r.output;
        EXPECT_NE(r.output.find(name), std::string::npos) << r.output;
        EXPECT_EQ(r.output.find("removed bvh"), std::string::npos) << r.output;
    }
    EXPECT_TRUE(fs::exists(root / "precious.txt"));
    EXPECT_TRUE(fs::exists(root / "elsewhere" / "0000000000000001.bin"));
    EXPECT_TRUE(fs::exists(cache.pathOf({"bvh", 0x1234})));
    EXPECT_EQ(vitrine("cache rm", env).status, 1);
    EXPECT_EQ(vitrine("cache rm bvh --all", env).status, 1);

    // One entry by its name: that file goes, the rest stays, and get() no longer finds it.
    const CliResult one = vitrine("cache rm bvh/0000000000001234.bin", env);
    ASSERT_EQ(one.status, 0) << one.output;
    EXPECT_NE(one.output.find("removed bvh/0000000000001234.bin (1.0 KiB)"), std::string::npos) << one.output;
    EXPECT_FALSE(fs::exists(cache.pathOf({"bvh", 0x1234})));
    EXPECT_FALSE(cache.get({"bvh", 0x1234}));
    ASSERT_TRUE(cache.get({"bvh", 0xabcdef}));

    // A whole kind.
    const CliResult kind = vitrine("cache rm reference", env);
    ASSERT_EQ(kind.status, 0) << kind.output;
    EXPECT_NE(kind.output.find("removed reference/0000000000000042.bin (3.0 MiB)"), std::string::npos) << kind.output;
    EXPECT_FALSE(fs::exists(cacheDir / "bake" / "reference"));
    EXPECT_TRUE(cache.get({"bvh", 0xabcdef}));

    // Everything.
    const CliResult all = vitrine("cache rm --all", env);
    ASSERT_EQ(all.status, 0) << all.output;
    EXPECT_NE(all.output.find("removed 2 entries"), std::string::npos) << all.output;
    EXPECT_FALSE(cache.get({"bvh", 0xabcdef}));
    EXPECT_TRUE(fs::exists(root / "precious.txt"));
    EXPECT_TRUE(fs::exists(root / "elsewhere" / "0000000000000001.bin"));
    const CliResult empty = vitrine("cache ls", env);
    EXPECT_EQ(empty.status, 0) << empty.output;
    EXPECT_NE(empty.output.find("no entries"), std::string::npos) << empty.output;

    const CliResult bad = vitrine("cache frobnicate", env);
    EXPECT_EQ(bad.status, 1);
    EXPECT_NE(bad.output.find("frobnicate"), std::string::npos) << bad.output;
}

} // namespace
} // namespace vitrine::test
