// PixelBuffer (core/scene/pixel_buffer.hpp): a texture's bytes, owned or a read-only view of memory someone else keeps
// alive (the bake cache's mapped file). A view is read in place, shared by copies, and never written: the first
// non-const access copies it into owned memory and lets go of what kept it alive.

#include "core/scene/hash.hpp"
#include "core/scene/material.hpp"

#include <memory>
#include <vector>

#include <gtest/gtest.h>

namespace vitrine::scene {
namespace {

struct Mapped {
    std::vector<uint8_t> bytes{1, 2, 3, 4, 5, 6, 7, 8};
};

TEST(PixelBuffer, AViewReadsTheMemoryInPlaceAndKeepsItAlive) {
    auto owner = std::make_shared<Mapped>();
    std::weak_ptr<Mapped> alive = owner;
    const uint8_t* where = owner->bytes.data();
    PixelBuffer view = PixelBuffer::view(std::span<const uint8_t>(owner->bytes).subspan(2, 4), owner);
    owner.reset();
    ASSERT_FALSE(alive.expired()) << "the view must hold what keeps its memory alive";
    const PixelBuffer& v = view;
    EXPECT_TRUE(v.isView());
    EXPECT_EQ(v.size(), 4u);
    EXPECT_EQ(v.data(), where + 2) << "a view is read where it lies, not copied";
    EXPECT_EQ(v[0], 3);
    EXPECT_EQ(v[3], 6);
    EXPECT_EQ(v, (std::vector<uint8_t>{3, 4, 5, 6}));
    {
        const PixelBuffer copy = view; // shares the memory
        EXPECT_TRUE(copy.isView());
        EXPECT_EQ(copy.data(), v.data());
    }
    view = PixelBuffer();
    EXPECT_TRUE(alive.expired()) << "the last view gone, the memory is let go";
}

TEST(PixelBuffer, WritingCopiesAViewAndLeavesTheSharedBytesAlone) {
    auto owner = std::make_shared<Mapped>();
    std::weak_ptr<Mapped> alive = owner;
    PixelBuffer a = PixelBuffer::view(owner->bytes, owner);
    const PixelBuffer b = a;
    const std::vector<uint8_t>& shared = owner->bytes;
    owner.reset();
    a[1] = 200; // non-const access: a becomes an owned copy
    EXPECT_FALSE(a.isView());
    EXPECT_EQ(a[1], 200);
    EXPECT_EQ(a[0], 1);
    EXPECT_EQ(a.size(), 8u);
    EXPECT_EQ(shared[1], 2) << "the viewed memory was written";
    EXPECT_TRUE(b.isView());
    EXPECT_EQ(b[1], 2);
    EXPECT_FALSE(alive.expired()) << "b still views it";
    PixelBuffer c = b;
    c.resize(10, 9);
    EXPECT_FALSE(c.isView());
    EXPECT_EQ(c.size(), 10u);
    EXPECT_EQ(c[7], 8);
    EXPECT_EQ(c[9], 9);
    PixelBuffer d = b;
    d.assign(3, 7); // replaced without copying the view first
    EXPECT_EQ(d, (std::vector<uint8_t>{7, 7, 7}));
}

TEST(PixelBuffer, HashesAndComparesLikeTheVectorOfItsBytes) {
    auto owner = std::make_shared<Mapped>();
    const PixelBuffer view = PixelBuffer::view(owner->bytes, owner);
    const PixelBuffer owned(owner->bytes);
    EXPECT_FALSE(owned.isView());
    EXPECT_EQ(view, owned);
    Hasher hv, ho, hvec;
    hv.array(view);
    ho.array(owned);
    hvec.array(owner->bytes);
    EXPECT_EQ(hv.result(), hvec.result());
    EXPECT_EQ(ho.result(), hvec.result());
    PixelBuffer other = owned;
    other[7] = 0;
    EXPECT_FALSE(other == view);
}

} // namespace
} // namespace vitrine::scene
