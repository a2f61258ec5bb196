#pragma once
// The bytes of a TextureImage: owned (a vector, as images are made and edited) or a read-only view of memory kept
// alive by someone else (the bake cache's mapped file of the museum's procedural textures, README "Caches"). A view
// avoids copying tens of MiB into fresh memory on a warm start: in a VM, first-touch page faults of fresh memory made
// that copy cost about 100 ms of the museum's 64 MiB, against a few ms to map the file's pages from the page cache.
//
// The interface is the part of std::vector<uint8_t> that images use. Const access reads either form; any non-const
// access (data(), operator[], begin(), resize(), ...) first turns a view into an owned copy, so writing through a
// PixelBuffer never touches the shared memory and never needs the caller to know which form it holds.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <span>
#include <utility>
#include <vector>

namespace vitrine::scene {

class PixelBuffer {
public:
    using value_type = uint8_t;
    using size_type = size_t;
    using iterator = uint8_t*;
    using const_iterator = const uint8_t*;

    PixelBuffer() = default;
    PixelBuffer(std::vector<uint8_t> bytes) : mOwned(std::move(bytes)) {} // NOLINT: implicit, as a vector converts
    PixelBuffer(std::initializer_list<uint8_t> bytes) : mOwned(bytes) {}

    // A view of `bytes`, valid while `keepAlive` lives (the buffer holds it).
    static PixelBuffer view(std::span<const uint8_t> bytes, std::shared_ptr<const void> keepAlive) {
        PixelBuffer b;
        b.mView = bytes;
        b.mKeepAlive = std::move(keepAlive);
        return b;
    }
    // True while the bytes are someone else's (no write has happened since view()).
    bool isView() const { return mKeepAlive != nullptr; }

    size_t size() const { return isView() ? mView.size() : mOwned.size(); }
    bool empty() const { return size() == 0; }
    const uint8_t* data() const { return isView() ? mView.data() : mOwned.data(); }
    const uint8_t& operator[](size_t i) const { return data()[i]; }
    const uint8_t* begin() const { return data(); }
    const uint8_t* end() const { return data() + size(); }

    uint8_t* data() { return own().data(); }
    uint8_t& operator[](size_t i) { return own()[i]; }
    uint8_t* begin() { return own().data(); }
    uint8_t* end() { return own().data() + mOwned.size(); }

    void resize(size_t n) { own().resize(n); }
    void resize(size_t n, uint8_t value) { own().resize(n, value); }
    template <class It>
    void assign(It first, It last) {
        drop();
        mOwned.assign(first, last);
    }
    void assign(size_t n, uint8_t value) {
        drop();
        mOwned.assign(n, value);
    }

    // The bytes as a vector (a copy).
    std::vector<uint8_t> toVector() const { return {begin(), end()}; }

    friend bool operator==(const PixelBuffer& a, const PixelBuffer& b) {
        return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
    }
    friend bool operator==(const PixelBuffer& a, const std::vector<uint8_t>& b) {
        return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin());
    }

private:
    std::vector<uint8_t>& own() {
        if (isView()) {
            mOwned.assign(mView.begin(), mView.end());
            mView = {};
            mKeepAlive.reset();
        }
        return mOwned;
    }
    void drop() {
        mView = {};
        mKeepAlive.reset();
    }

    std::vector<uint8_t> mOwned;
    std::span<const uint8_t> mView;
    std::shared_ptr<const void> mKeepAlive; // non-null exactly when the buffer is a view
};

} // namespace vitrine::scene
