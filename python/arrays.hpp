// The module's inputs checked and read: numpy arrays (or anything numpy.asarray accepts) of the
// shape and kind an argument needs, with every refusal a ValueError naming the argument. Float32
// C-contiguous aligned arrays are read in place; anything else is converted once, by numpy.
#pragma once

#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

#include "cellrt/triangle.hpp"

namespace cellrt::python {

namespace py = pybind11;

// Rows of `columns` float32 values, `rows` of them: the argument read in place (`borrowed`) or a
// float32 copy numpy made of it, held by `array` as long as the view lives.
struct FloatRows {
    py::array array;
    const float* data = nullptr;
    std::size_t rows = 0;
    bool borrowed = false;
    py::array source;  // the array as given, of which `array` may be a converted copy
};

// Where the values of `rows` at `index` (an int, or a tuple for triangles) were finite floats wider
// than float32 whose copy overflowed: "LABEL = [1e+300, 0.0, 0.0] is beyond float32's range (about
// 3.4e38)" (reported as an infinity until found by audit, 2026-12-07); else nullopt.
std::optional<std::string> beyond_float32(const FloatRows& rows, const py::object& index, const std::string& label);

// Why the float32 values `p` of `rows` at `index` are refused: beyond_float32's message, else
// "LABEL = (inf, 0.0, 0.0) is not finite".
std::string non_finite_message(const FloatRows& rows, const py::object& index, const std::string& label, const float* p);

// `object` as an (N, columns) float array (integers and float64 converted to float32); `name` is the
// argument's name for messages. Refuses another shape or a dtype that is not a real number; values
// are the caller's to check (the rays check theirs while they are traced, in one pass).
FloatRows float_rows(py::handle object, const std::string& name, std::size_t columns);

// The same in two steps, so that sizes can be compared before anything is copied: the argument as an
// (N, columns) array of real numbers, then its float32 rows.
py::array row_array(py::handle object, const std::string& name, std::size_t columns);
FloatRows float_rows(const py::array& rows, const std::string& name);

// The same for an (M, 3, 3) array of triangles, refused before it is copied where there are more than a
// uint32 index can name.
FloatRows triangle_rows(py::handle object, const std::string& name);

// A ray bound (tnear, tfar): a scalar for every ray, or one float32 per ray. NaN is refused. A value
// float32 cannot hold (float64, a large integer) is rounded inward, toward the other bound (`up` for
// tnear, `down` for tfar), so that no hit outside the bounds given is reported.
enum class Inward { up, down };
struct Bound {
    FloatRows values;      // empty rows: the scalar
    float scalar = 0.f;
    bool per_ray() const { return values.data != nullptr; }
    float at(std::size_t i) const { return per_ray() ? values.data[i] : scalar; }
};
Bound ray_bound(py::handle object, const std::string& name, std::size_t rays, Inward inward);

// Triangles from vertices (N, 3) and faces (M, 3) of integers, every index checked against N, every
// used vertex checked finite.
std::vector<Triangle> indexed_triangles(py::handle vertices, py::handle faces);

// Triangles from an (M, 3, 3) array, every coordinate checked finite.
std::vector<Triangle> triangle_soup(py::handle triangles);

// A point or vector: three finite numbers.
Vec3 vec3_value(py::handle object, const std::string& name);

// Whether `object` is a numpy scalar (not an array) whose dtype is of `kind`: 'b' bool, 'i' and 'u'
// integers, 'f' floats.
bool is_numpy_kind(py::handle object, char kind);
// A Python bool or a numpy one (np.bool_ is no subclass of bool, and numpy lets it serve as an index).
bool is_bool(py::handle object);

// An integer in [min, max], refused as ValueError naming `name` otherwise; a bool,
// Python's or numpy's, is refused too.
unsigned small_count(py::handle object, const std::string& name, unsigned max, unsigned min = 0);

// A str argument as UTF-8 bytes; ValueError naming `name` for anything else, for text UTF-8 cannot
// encode (a lone surrogate) and for a NUL. With `file_name`, lone surrogates become the bytes they
// stand for, as os.fsencode makes them: a name the system gave in bytes that are not UTF-8.
std::string text(py::handle object, const std::string& name, bool file_name = false);

// Whether an error raised while an argument was read must reach the caller as it is, not as a
// ValueError naming the argument: MemoryError, which says nothing of the argument, and what is not an
// Exception (KeyboardInterrupt, SystemExit), which a caller's `except ValueError` would swallow.
bool passes_through(const py::error_already_set& e);

// The array's shape as Python prints it: "(5, 4)".
std::string shape_of(const py::array& a);

}  // namespace cellrt::python
