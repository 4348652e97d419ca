#include "arrays.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string_view>

#include "cellrt/ray.hpp"
#include "interpreter_exit.hpp"

namespace cellrt::python {
namespace {

py::module_ numpy() { return py::module_::import("numpy"); }

// What numpy said, without the exception type's name.
std::string message_of(const py::error_already_set& e) { return py::str(e.value()).cast<std::string>(); }

py::array as_array(py::handle object, const std::string& name) {
    if (py::isinstance<py::array>(object)) {
        // numpy reads a masked array's data under its mask too: the entries the caller masked out
        // would be traced or built as if they were not. Asked of ndarray's subclasses only, so that a
        // plain array costs one compare.
        if (Py_TYPE(object.ptr()) != py::detail::npy_api::get().PyArray_Type_) {
            const py::object ma = numpy().attr("ma");
            if (py::isinstance(object, ma.attr("MaskedArray")) &&
                call_python(ma.attr("is_masked"), py::make_tuple(object)).cast<bool>())
                throw py::value_error(name + " is a masked array with masked entries, whose values would be used; " +
                                      "pass " + name + ".filled(...) or only the rows to use");
        }
        return py::reinterpret_borrow<py::array>(object);
    }
    try {
        return call_python(numpy().attr("asarray"), py::make_tuple(object));
    } catch (py::error_already_set& e) {
        if (passes_through(e)) throw;
        throw py::value_error(name + " is not an array: " + message_of(e));
    }
}

std::string dtype_of(const py::array& a) { return py::str(a.dtype()).cast<std::string>(); }

void check_real(const py::array& a, const std::string& name) {
    const char kind = a.dtype().kind();
    if (kind == 'O')  // numpy's answer to a Python integer past 64 bits, or to values of mixed types
        throw py::value_error(name + " must hold real numbers, got Python objects (an integer past 64 bits, or a "
                                     "value numpy holds as no number); pass floats");
    if (kind != 'f' && kind != 'i' && kind != 'u')
        throw py::value_error(name + " must hold real numbers, got dtype " + dtype_of(a));
}

// `a` as a C-contiguous, aligned array of `dtype`: `a` itself where it is one already (float32 asked
// of a native float32 array without a call: numpy.require is Python code, run for every call's
// arrays and bounds).
py::array required(const py::array& a, const char* dtype, const std::string& name) {
    if (std::string_view(dtype) == "float32" && py::isinstance<py::array_t<float, py::array::c_style>>(a) &&
        (a.flags() & py::detail::npy_api::NPY_ARRAY_ALIGNED_) != 0)
        return a;
    try {
        return call_python(numpy().attr("require"), py::make_tuple(a, dtype, "CA"));
    } catch (py::error_already_set& e) {
        if (passes_through(e)) throw;
        throw py::value_error(name + " cannot be converted to " + dtype + ": " + message_of(e));
    }
}

FloatRows rows_of(const py::array& a, const std::string& name, std::size_t rows) {
    FloatRows r;
    r.source = a;
    if (a.dtype().kind() == 'f' && a.dtype().itemsize() > 4) {
        // numpy warns of the overflow of a value past float32 (a RuntimeWarning pointing into numpy),
        // which non_finite_message names instead.
        py::dict over;
        over["over"] = "ignore";
        const py::object quiet = call_python(numpy().attr("errstate"), py::tuple(), over);
        call_python(quiet.attr("__enter__"), py::tuple());
        const py::tuple no_exception = py::make_tuple(py::none(), py::none(), py::none());
        try {
            r.array = required(a, "float32", name);
        } catch (...) {
            call_python(quiet.attr("__exit__"), no_exception);
            throw;
        }
        call_python(quiet.attr("__exit__"), no_exception);
    } else {
        r.array = required(a, "float32", name);
    }
    r.data = static_cast<const float*>(r.array.data());
    r.rows = rows;
    r.borrowed = r.array.data() == a.data();
    return r;
}

std::string vec_text(const float* p) {
    return "(" + py::repr(py::float_(p[0])).cast<std::string>() + ", " + py::repr(py::float_(p[1])).cast<std::string>() +
           ", " + py::repr(py::float_(p[2])).cast<std::string>() + ")";
}

bool finite3(const float* p) { return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]); }


// Hits name triangles by a uint32 index, kNoHit reserved for a miss.
void check_triangle_count(std::size_t count, const std::string& name) {
    if (count >= kNoHit)
        throw py::value_error(name + " has " + std::to_string(count) + " triangles; at most " +
                              std::to_string(kNoHit - 1) + " are indexable");
}

}  // namespace

std::optional<std::string> beyond_float32(const FloatRows& rows, const py::object& index, const std::string& label) {
    if (rows.borrowed || rows.source.dtype().kind() != 'f') return std::nullopt;
    const py::object given = rows.source.attr("__getitem__")(index);
    if (!numpy().attr("isfinite")(given).attr("all")().cast<bool>()) return std::nullopt;
    return label + " = " + py::repr(given.attr("tolist")()).cast<std::string>() +
           " is beyond float32's range (about 3.4e38)";
}

std::string non_finite_message(const FloatRows& rows, const py::object& index, const std::string& label, const float* p) {
    return beyond_float32(rows, index, label).value_or(label + " = " + vec_text(p) + " is not finite");
}

bool passes_through(const py::error_already_set& e) {
    return e.matches(PyExc_MemoryError) || !e.matches(PyExc_Exception);
}

std::string shape_of(const py::array& a) {
    std::string s = "(";
    for (py::ssize_t i = 0; i < a.ndim(); ++i) s += (i ? ", " : "") + std::to_string(a.shape(i));
    return s + (a.ndim() == 1 ? ",)" : ")");
}

py::array row_array(py::handle object, const std::string& name, std::size_t columns) {
    const py::array a = as_array(object, name);
    if (a.ndim() != 2 || a.shape(1) != static_cast<py::ssize_t>(columns))
        throw py::value_error(name + " must have shape (N, " + std::to_string(columns) + "), got " + shape_of(a));
    check_real(a, name);
    return a;
}

FloatRows float_rows(const py::array& rows, const std::string& name) {
    return rows_of(rows, name, static_cast<std::size_t>(rows.shape(0)));
}

FloatRows float_rows(py::handle object, const std::string& name, std::size_t columns) {
    return float_rows(row_array(object, name, columns), name);
}

FloatRows triangle_rows(py::handle object, const std::string& name) {
    const py::array a = as_array(object, name);
    if (a.ndim() != 3 || a.shape(1) != 3 || a.shape(2) != 3)
        throw py::value_error(name + " must have shape (M, 3, 3), got " + shape_of(a) +
                              " (vertices of shape (N, 3) need faces)");
    check_real(a, name);
    check_triangle_count(static_cast<std::size_t>(a.shape(0)), name);  // before a copy of them all is made
    return rows_of(a, name, static_cast<std::size_t>(a.shape(0)));
}

namespace {

// `x` as the float32 on the bound's inner side: the nearest float, stepped once toward the inside where
// rounding to nearest crossed `x` (tfar = 1 - 1e-8 in float64 is 1.0f to nearest, which would let a hit
// at t = 1 through). A NaN stays NaN (both compares are false), for the caller to refuse.
template <class T>
float inner_float(T x, Inward inward) {
    float f = static_cast<float>(x);
    if (inward == Inward::down && static_cast<T>(f) > x) f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    if (inward == Inward::up && static_cast<T>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
    return f;
}

// The bound's values as float32: float32 read as they are, other floats and integers rounded inward,
// compared exactly in a type that holds both (integers in 128 bits: a float past 2^63 is still an
// integer there).
py::array_t<float> inner_floats(const py::array& a, const std::string& name, Inward inward) {
    const char kind = a.dtype().kind();
    py::array_t<float> out(a.size());
    float* o = out.mutable_data();
    const auto each = [&](const char* dtype, auto convert) {
        const py::array r = required(a, dtype, name);
        for (py::ssize_t i = 0; i < a.size(); ++i) o[i] = convert(i, r.data());
    };
    if (kind == 'f' && a.itemsize() == 4) {
        each("float32", [](py::ssize_t i, const void* d) { return static_cast<const float*>(d)[i]; });
    } else if (kind == 'f' && a.itemsize() <= 8) {
        each("float64", [&](py::ssize_t i, const void* d) {
            return inner_float(static_cast<const double*>(d)[i], inward);
        });
    } else if (kind == 'f') {
        each("longdouble", [&](py::ssize_t i, const void* d) {
            return inner_float(static_cast<const long double*>(d)[i], inward);
        });
    } else if (kind == 'u') {
        each("uint64", [&](py::ssize_t i, const void* d) {
            return inner_float(static_cast<unsigned __int128>(static_cast<const std::uint64_t*>(d)[i]), inward);
        });
    } else {
        each("int64", [&](py::ssize_t i, const void* d) {
            return inner_float(static_cast<__int128>(static_cast<const std::int64_t*>(d)[i]), inward);
        });
    }
    return out;
}

}  // namespace

Bound ray_bound(py::handle object, const std::string& name, std::size_t rays, Inward inward) {
    const py::array a = as_array(object, name);
    check_real(a, name);
    Bound b;
    if (a.ndim() == 0) {
        b.scalar = inner_floats(a, name, inward).data()[0];
        if (std::isnan(b.scalar)) throw py::value_error(name + " is NaN");
        return b;
    }
    if (a.ndim() != 1)
        throw py::value_error(name + " must be a scalar or have shape (N,), got " + shape_of(a));
    if (static_cast<std::size_t>(a.shape(0)) != rays)
        throw py::value_error(name + " has " + std::to_string(a.shape(0)) + " values for " + std::to_string(rays) +
                              " rays");
    if (a.dtype().kind() == 'f' && a.itemsize() == 4) {
        b.values = rows_of(a, name, rays);
    } else {
        b.values.array = inner_floats(a, name, inward);
        b.values.data = static_cast<const float*>(b.values.array.data());
        b.values.rows = rays;
    }
    return b;
}

// Faces that numpy could hold only as Python objects (integers past 64 bits, or values of mixed
// types), as indices: each must be an integer (Python's or numpy's bools excluded; anything
// operator.index takes included, which is the value used) in [0, vertices), or the first that is
// not is named, as for an integer array.
std::vector<std::int64_t> object_face_indices(const py::array& f, std::size_t vertices) {
    const py::list rows = f.attr("tolist")();
    const py::object index = py::module_::import("operator").attr("index");
    const py::object numpy_bool = numpy().attr("bool_");
    const py::int_ zero(0), count(vertices);
    std::vector<std::int64_t> out;
    out.reserve(3 * rows.size());
    for (std::size_t t = 0; t < rows.size(); ++t) {
        const py::list row = rows[t];
        for (std::size_t c = 0; c < 3; ++c) {
            const py::object x = row[c];
            const auto at = [&] { return "faces[" + std::to_string(t) + ", " + std::to_string(c) + "] = "; };
            py::object k;
            if (!py::isinstance<py::bool_>(x) && !py::isinstance(x, numpy_bool)) {
                try {
                    k = index(x);
                } catch (py::error_already_set& e) {
                    if (passes_through(e)) throw;
                }
            }
            if (!k) throw py::value_error(at() + py::repr(x).cast<std::string>() + " is not an integer");
            if (k < zero || k >= count)
                throw py::value_error(at() + py::str(k).cast<std::string>() + " is out of range for " +
                                      std::to_string(vertices) + " vertices");
            out.push_back(k.cast<std::int64_t>());
        }
    }
    return out;
}

std::vector<Triangle> indexed_triangles(py::handle vertices, py::handle faces) {
    // Both arguments' shapes and kinds before either is copied.
    const py::array va = row_array(vertices, "vertices", 3);
    const py::array f = as_array(faces, "faces");
    if (f.ndim() != 2 || f.shape(1) != 3)
        throw py::value_error("faces must have shape (M, 3), got " + shape_of(f));
    const char kind = f.dtype().kind();
    if (kind != 'i' && kind != 'u' && kind != 'O')
        throw py::value_error("faces must hold integers, got dtype " + dtype_of(f));
    const std::size_t m = static_cast<std::size_t>(f.shape(0));
    check_triangle_count(m, "faces");
    const FloatRows v = float_rows(va, "vertices");
    for (std::size_t i = 0; i < v.rows; ++i)
        if (!finite3(v.data + 3 * i))
            throw py::value_error(
                non_finite_message(v, py::int_(i), "vertices[" + std::to_string(i) + "]", v.data + 3 * i));
    // uint64 indices beyond int64 wrap to negative values, which the range check refuses.
    std::vector<std::int64_t> objects;
    py::array idx;
    if (kind == 'O') objects = object_face_indices(f, v.rows);
    else idx = required(f, "int64", "faces");
    const auto* index = kind == 'O' ? objects.data() : static_cast<const std::int64_t*>(idx.data());
    std::vector<Triangle> tris(m);
    for (std::size_t t = 0; t < m; ++t) {
        Vec3* corner = &tris[t].v0;
        for (std::size_t c = 0; c < 3; ++c) {
            const std::int64_t k = index[3 * t + c];
            if (k < 0 || static_cast<std::uint64_t>(k) >= v.rows)
                throw py::value_error("faces[" + std::to_string(t) + ", " + std::to_string(c) + "] = " +
                                      (kind == 'u' ? std::to_string(static_cast<std::uint64_t>(k)) : std::to_string(k)) +
                                      " is out of range for " + std::to_string(v.rows) + " vertices");
            const float* p = v.data + 3 * k;
            corner[c] = Vec3{p[0], p[1], p[2]};
        }
    }
    return tris;
}

std::vector<Triangle> triangle_soup(py::handle triangles) {
    const FloatRows r = triangle_rows(triangles, "triangles");
    std::vector<Triangle> tris(r.rows);
    for (std::size_t t = 0; t < r.rows; ++t)
        for (std::size_t c = 0; c < 3; ++c) {
            const float* p = r.data + 9 * t + 3 * c;
            if (!finite3(p))
                throw py::value_error(non_finite_message(
                    r, py::make_tuple(t, c), "triangles[" + std::to_string(t) + ", " + std::to_string(c) + "]", p));
            (&tris[t].v0)[c] = Vec3{p[0], p[1], p[2]};
        }
    return tris;
}

Vec3 vec3_value(py::handle object, const std::string& name) {
    const py::array a = as_array(object, name);
    if (a.ndim() != 1 || a.shape(0) != 3) throw py::value_error(name + " must have shape (3,), got " + shape_of(a));
    check_real(a, name);
    const FloatRows f = rows_of(a, name, 1);  // held: a converted copy lives as long as it
    const float* p = f.data;
    if (!finite3(p)) throw py::value_error(non_finite_message(f, py::slice(py::none(), py::none(), py::none()), name, p));
    return Vec3{p[0], p[1], p[2]};
}

namespace {

// object.name, or None where it has no such attribute; any other error raised (Ctrl-C in a property)
// reaches the caller, where py::hasattr would swallow it.
py::object attribute_or_none(py::handle object, const char* name) {
    PyObject* value = PyObject_GetAttrString(object.ptr(), name);
    if (value) return py::reinterpret_steal<py::object>(value);
    if (!PyErr_ExceptionMatches(PyExc_AttributeError)) throw py::error_already_set();
    PyErr_Clear();
    return py::none();
}

}  // namespace

bool is_numpy_kind(py::handle object, char kind) {
    if (py::isinstance<py::array>(object)) return false;
    const py::object dtype = attribute_or_none(object, "dtype");
    if (dtype.is_none()) return false;
    const py::object k = attribute_or_none(dtype, "kind");
    return !k.is_none() && py::str(k).cast<std::string>() == std::string(1, kind);
}

bool is_bool(py::handle object) { return py::isinstance<py::bool_>(object) || is_numpy_kind(object, 'b'); }

unsigned small_count(py::handle object, const std::string& name, unsigned max, unsigned min) {
    const std::string range = " must be an integer in [" + std::to_string(min) + ", " + std::to_string(max) + "]";
    if (is_bool(object) || PyIndex_Check(object.ptr()) == 0)
        throw py::value_error(name + range + ", got " + py::repr(object).cast<std::string>());
    // Every numpy array passes PyIndex_Check; one that is not an integer scalar raised numpy's bare
    // TypeError (found by audit, 2026-12-07). An __index__ of the caller's own that raises otherwise
    // keeps its exception.
    const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(object.ptr()));
    if (!index) {
        if (!PyErr_ExceptionMatches(PyExc_TypeError)) throw py::error_already_set();
        PyErr_Clear();
        throw py::value_error(name + range + ", got " + py::repr(object).cast<std::string>());
    }
    int overflow = 0;
    const long long value = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
    if (overflow != 0 || value < static_cast<long long>(min) || value > static_cast<long long>(max))
        throw py::value_error(name + range + ", got " + py::repr(index).cast<std::string>());
    return static_cast<unsigned>(value);
}

std::string text(py::handle object, const std::string& name, bool file_name) {
    if (!py::isinstance<py::str>(object))
        throw py::value_error(name + " must be a str, got " + py::repr(object).cast<std::string>());
    PyObject* bytes = PyUnicode_AsEncodedString(object.ptr(), "utf-8", file_name ? "surrogateescape" : "strict");
    if (!bytes) {
        PyErr_Clear();
        throw py::value_error(name + " must be text that UTF-8 can encode, got " + py::repr(object).cast<std::string>());
    }
    const std::string s = py::reinterpret_steal<py::bytes>(bytes);
    // The library's messages are C strings: a NUL would cut the name it is refused with.
    if (s.find('\0') != std::string::npos)
        throw py::value_error(name + " must not contain a NUL character, got " + py::repr(object).cast<std::string>());
    return s;
}

}  // namespace cellrt::python
