#pragma once

// A streaming 64-bit hash for content hashes (determinism tests, bake-cache keys). Not cryptographic;
// stable across runs, builds and platforms of the same endianness. Used by core/scene, and by core/bake
// and core/accel for bake-cache checksums and keys.

#include <cstdint>
#include <cstring>
#include <string_view>
#include <type_traits>
#include <vector>

namespace vitrine::scene {

class Hasher {
public:
    void bytes(const void* data, size_t size) {
        const auto* p = static_cast<const uint8_t*>(data);
        size_t words = size / 8;
        for (size_t i = 0; i < words; ++i) {
            uint64_t w;
            std::memcpy(&w, p + i * 8, 8);
            mix(w);
        }
        uint64_t tail = 0;
        if (size > words * 8) std::memcpy(&tail, p + words * 8, size - words * 8);
        mix(tail ^ (static_cast<uint64_t>(size) << 56));
    }

    template <typename T> void value(const T& v) {
        static_assert(std::is_trivially_copyable_v<T>);
        bytes(&v, sizeof(T));
    }
    // A contiguous range (std::vector, PixelBuffer): its length, then its elements' bytes.
    template <typename R> void array(const R& v) {
        using T = std::remove_cvref_t<decltype(*v.data())>;
        static_assert(std::is_trivially_copyable_v<T>);
        value(v.size());
        if (!v.empty()) bytes(v.data(), v.size() * sizeof(T));
    }
    void string(std::string_view s) {
        value(s.size());
        bytes(s.data(), s.size());
    }

    // One 8-byte word, mixed as bytes() mixes each whole word (without bytes()'s length word): for callers that
    // split a stream into lanes of words themselves (the bake cache's checksum).
    void word(uint64_t w) { mix(w); }

    uint64_t result() const {
        // Final avalanche (splitmix64's) so that nearby states give unrelated hashes.
        uint64_t z = mState;
        z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
        z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
        return z ^ (z >> 31);
    }

private:
    void mix(uint64_t w) {
        // One lane of xxHash64's round: fast, and each input word changes the whole state.
        mState ^= (w * 0xc2b2ae3d27d4eb4full);
        mState = ((mState << 31) | (mState >> 33)) * 0x9e3779b185ebca87ull + 0x27d4eb2f165667c5ull;
    }

    uint64_t mState = 0x84222325cbf29ce4ull;
};

} // namespace vitrine::scene
