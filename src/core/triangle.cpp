#include "cellrt/triangle.hpp"

#include <string>

#include "cellrt/error.hpp"

namespace cellrt {

void check_finite(std::span<const Triangle> triangles) {
    for (std::size_t i = 0; i < triangles.size(); ++i) {
        const Triangle& t = triangles[i];
        if (!is_finite(t.v0) || !is_finite(t.v1) || !is_finite(t.v2))
            throw Error("triangle " + std::to_string(i) + " has a non-finite coordinate");
    }
}

}  // namespace cellrt
