// The kd-tree builder's events (Wald & Havran 2006, section 4): where a triangle's box starts, ends or
// lies flat on an axis, packed into one integer whose order is the sweep order; and a reference,
// a triangle with its (clipped) box, as binning sees it.
#pragma once

#include <bit>
#include <cstdint>

#include "cellrt/box.hpp"

namespace cellrt::detail::kdbuild {

// The low 30 bits of an event name its triangle: at most 2^30 triangles.
inline constexpr std::uint32_t kTriangleMask = (1u << 30) - 1;

// Event types in sweep order at equal positions: ends before planars before starts (W&H section 4.2).
enum EventType : std::uint32_t { kEnd = 0, kPlanar = 1, kStart = 2 };

// An event packed into one integer whose order is the sweep order (position, type, triangle): the
// high half holds the position's float bits mapped to an unsigned integer of the same order (all bits
// of a negative flipped, the sign bit of the rest set), the low half type << 30 | triangle. A
// triangle has one event of each type per axis, so no two events of a list are equal: every correct
// sort or merge of a list gives the same sequence. One difference from the order of floats: that has
// -0 == +0 (and orders the events there by type and triangle), the integers put -0 just before +0;
// the sweep treats both as one position (run_position).
class Event {
public:
    Event() = default;
    Event(float pos, EventType type, std::uint32_t triangle)
        : bits_(std::uint64_t{ordered(pos)} << 32 | type << 30 | triangle) {}

    float pos() const {
        const auto o = static_cast<std::uint32_t>(bits_ >> 32);
        return std::bit_cast<float>(o & kSign ? o & ~kSign : ~o);
    }
    // The ordered position with -0 taken as +0: equal exactly for equal floats.
    std::uint32_t position_class() const {
        const auto o = static_cast<std::uint32_t>(bits_ >> 32);
        return o == kNegativeZero ? kSign : o;
    }
    std::uint32_t key() const { return static_cast<std::uint32_t>(bits_); }
    EventType type() const { return static_cast<EventType>(key() >> 30); }
    std::uint32_t triangle() const { return key() & kTriangleMask; }
    friend bool operator<(Event a, Event b) { return a.bits_ < b.bits_; }

    // The least event past every event at this one's position (-0 and +0 being one position): in a
    // sorted list, the events at this position are those from it up to, not including, this bound.
    Event next_position() const {
        Event e;
        e.bits_ = (std::uint64_t{position_class()} + 1) << 32;
        return e;
    }

    // Greater than every event (their positions are finite): ends a list for a merge without bounds checks.
    static Event sentinel() {
        Event e;
        e.bits_ = ~std::uint64_t{0};
        return e;
    }

private:
    static constexpr std::uint32_t kSign = 1u << 31;
    static constexpr std::uint32_t kNegativeZero = ~kSign;  // ordered(-0.f)
    static std::uint32_t ordered(float f) {
        const auto b = std::bit_cast<std::uint32_t>(f);
        return b & kSign ? ~b : b | kSign;
    }
    std::uint64_t bits_;
};

struct Ref {
    std::uint32_t triangle;
    Box3 box;
};

}  // namespace cellrt::detail::kdbuild
