// The Python module `cellrt` (docs/PYTHON.md): accelerators over numpy triangles, batches of rays
// traced on all threads without the GIL, scenes and the renderer. A consumer of the public API
// (cellrt/accel.hpp, cellrt/scene.hpp, cellrt/render.hpp), as the programs are.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <limits>
#include <memory>
#include <optional>

#include "arrays.hpp"
#include "batch.hpp"
#include "interpreter_exit.hpp"
#include "cellrt/accel.hpp"
#include "cellrt/camera.hpp"
#include "cellrt/device.hpp"
#include "cellrt/error.hpp"
#include "cellrt/render.hpp"
#include "cellrt/scene.hpp"
#include "cellrt/version.hpp"

namespace cellrt::python {
namespace {

// An accelerator and what it reads: the kd-tree and brute force read the triangles on every call
// (cellrt/accel.hpp), so they live as long as it, out of Python's reach.
struct PyAccelerator {
    std::vector<Triangle> triangles;
    std::unique_ptr<Accelerator> accel;
    Team team;
    AccelConfig config;  // as built
};

// The GIL taken back after a call that released it (interpreter_exit.hpp): a thread that took it
// back while the interpreter finalizes ran pybind11's destructors without the GIL (a segmentation
// fault) or unwound out of py::gil_scoped_release's noexcept destructor (std::terminate), for a
// daemon thread in any call at exit (found by audit, 2026-12-07). An atexit callback that joins a
// thread coming back before finalization still can.
void take_gil_back(PyThreadState* state) {
    unless_the_interpreter_ends([&] { PyEval_RestoreThread(state); });
}

// Runs `f` with the GIL released, taken back by take_gil_back (never in a destructor). Every caller
// returns a value.
template <class F>
auto without_gil(F&& f) {
    PyThreadState* const state = PyEval_SaveThread();
    std::optional<decltype(f())> result;
    try {
        result.emplace(f());
    } catch (...) {
        take_gil_back(state);
        throw;
    }
    take_gil_back(state);
    return std::move(*result);
}

}  // namespace
}  // namespace cellrt::python

namespace pybind11::detail {

// Every class of the module is read through a caster that refuses an object whose C++ value was
// never made: `cellrt.Accelerator.__new__(cellrt.Accelerator)` without `__init__` (or `__new__` of a
// class made only by the library, such as AccelStats) gives an object whose memory pybind11 (2.10)
// allocated but did not construct, and hands that memory to the methods. pybind11 registers a value
// when a constructor has made it, or when it wraps one the library owns (`scene.camera`), never
// before: the registration tells.
template <class T>
struct made_caster : type_caster_base<T> {
    bool load(handle src, bool convert) {
        if (!type_caster_base<T>::load(src, convert)) return false;
        if (this->value == nullptr) return true;  // None, where the argument allows it
        // A value converted from another object (none of the module's classes allows it today) was made.
        if (!PyObject_TypeCheck(src.ptr(), reinterpret_cast<PyTypeObject*>(get_internals().instance_base))) return true;
        const value_and_holder v_h =
            reinterpret_cast<instance*>(src.ptr())->get_value_and_holder(get_type_info(typeid(T)), false);
        if (v_h.vh == nullptr || !v_h.instance_registered())  // vh: found (its operator bool reads *vh)
            throw type_error(std::string(Py_TYPE(src.ptr())->tp_name) +
                             " object was made by __new__ without __init__: make it by calling the class");
        return true;
    }
};

template <>
struct type_caster<cellrt::python::PyAccelerator> : made_caster<cellrt::python::PyAccelerator> {};
template <>
struct type_caster<cellrt::Scene> : made_caster<cellrt::Scene> {};
template <>
struct type_caster<cellrt::Camera> : made_caster<cellrt::Camera> {};
template <>
struct type_caster<cellrt::PointLight> : made_caster<cellrt::PointLight> {};
template <>
struct type_caster<cellrt::AccelStats> : made_caster<cellrt::AccelStats> {};
template <>
struct type_caster<cellrt::TreeReport> : made_caster<cellrt::TreeReport> {};

}  // namespace pybind11::detail

namespace cellrt::python {
namespace {

// A second `__init__` on an object already made: pybind11 (2.10) skips it and returns None without
// reading its arguments, so that `acc.__init__(v, f, kind="bvh")` left the old accelerator in place
// without a word. Each class's `__init__` is wrapped so that such a call raises TypeError; a first
// call (the class called, or a subclass's `super().__init__`) goes on to pybind11's own.
template <class T, class... Options>
void refuse_second_init(py::class_<T, Options...>& cls) {
    static const std::string doc = py::str(cls.attr("__init__").attr("__doc__"));
    // The wrapper's own signature line, init_once(self, *args, **kwargs), would come first in help():
    // the docstring is pybind11's own for the wrapped __init__, signature line included.
    py::options no_signature;
    no_signature.disable_function_signatures();
    cls.attr("__init__") = py::cpp_function(
        [made_by = py::object(cls.attr("__init__")), type = py::object(cls)](py::handle self, py::args args,
                                                                               py::kwargs kwargs) {
            if (PyObject_TypeCheck(self.ptr(), reinterpret_cast<PyTypeObject*>(type.ptr()))) {
                const py::detail::value_and_holder v_h = reinterpret_cast<py::detail::instance*>(self.ptr())
                    ->get_value_and_holder(py::detail::get_type_info(typeid(T)), false);
                if (v_h.vh != nullptr && v_h.instance_registered())
                    throw py::type_error(std::string(Py_TYPE(self.ptr())->tp_name) +
                                         " object is already made: __init__ runs once; call the class for a new one");
            }
            made_by(self, *args, **kwargs);
        },
        // Not named __init__: pybind11 takes a function of that name for a constructor and would skip it too.
        py::name("init_once"), py::is_method(cls), py::doc(doc.c_str()));
}

// Text the library made from a file's name, in whatever bytes the system gave: bytes that are not
// UTF-8 come back as lone surrogates, as os.fsdecode gives them, so that the name round-trips.
py::str decoded(const std::string& bytes) {
    PyObject* text = PyUnicode_DecodeUTF8(bytes.data(), static_cast<Py_ssize_t>(bytes.size()), "surrogateescape");
    if (!text) throw py::error_already_set();
    return py::reinterpret_steal<py::str>(text);
}

// numpy's scalars count as what they hold: np.int64(2) as 2, np.bool_(True) as true, np.float32(0.5)
// as 0.5 (np.int64 was refused, np.float64, a float subclass, taken).
std::string param_value(py::handle value, const std::string& name) {
    if (py::isinstance<py::str>(value)) return text(value, name);
    if (is_bool(value)) return PyObject_IsTrue(value.ptr()) ? "true" : "false";
    if (PyIndex_Check(value.ptr()) != 0) {
        // Every numpy array passes PyIndex_Check; np.array([1]) raised numpy's bare TypeError.
        if (const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()))) return py::str(index);
        if (!PyErr_ExceptionMatches(PyExc_TypeError)) throw py::error_already_set();
        PyErr_Clear();
    }
    if (py::isinstance<py::float_>(value) || is_numpy_kind(value, 'f'))
        return py::repr(py::float_(py::reinterpret_borrow<py::object>(value))).cast<std::string>();
    throw py::value_error(name + " must be a str, bool, int or float, got " + py::repr(value).cast<std::string>());
}

// kind "KIND[:TRAVERSAL]", the SIMD set, the build threads, the structure's parameters and the device.
// kind None is the library's default for the device (default_accel_config: `auto@packets=bvh` on the
// CPU, `kd` on the GPU), to which `params` add or override parameters.
// On the GPU (device "cuda") simd "auto" is its own one-ray-a-thread kernels, as the CLI's --device
// cuda without --simd; any other SIMD set is refused there by the library.
AccelConfig accel_config(py::handle kind, py::handle simd, py::handle threads, py::handle params, py::handle device) {
    const std::string place = text(device, "device");
    AccelConfig c = default_accel_config(place);
    if (!kind.is_none()) {
        const std::string spec = text(kind, "kind");
        if (spec.find_first_of("+@") != std::string::npos)
            throw py::value_error("kind '" + spec + "' must be KIND or KIND:TRAVERSAL; pass the SIMD set as simd= "
                                  "and parameters as params=");
        c = parse_accel_config(spec);
    }
    // None: the best packets, or one ray at a time where kind names a tree's single-ray kernel, which
    // packets would replace (names_replaced_traversal; a SIMD set given with one is refused).
    c.simd = simd.is_none() ? "auto" : text(simd, "simd");
    if (simd.is_none() && names_replaced_traversal(c)) c.simd = "off";
    c.device = place;
    if (c.device == "cuda" && c.simd == "auto") c.simd = "off";
    c.threads = small_count(threads, "threads", kMaxWorkers);
    if (!py::isinstance<py::dict>(params))
        throw py::value_error("params must be a dict of name: value, got " + py::repr(params).cast<std::string>());
    for (const auto& [key, value] : py::reinterpret_borrow<py::dict>(params)) {
        const std::string name = text(key, "a key of params");
        c.params[name] = param_value(value, "params['" + name + "']");
    }
    return c;
}

std::unique_ptr<PyAccelerator> build(std::vector<Triangle> triangles, const AccelConfig& config) {
    auto a = std::make_unique<PyAccelerator>(PyAccelerator{std::move(triangles), nullptr, Team(config.threads), config});
    a->accel = without_gil([&] { return make_accelerator(a->triangles, config); });
    return a;
}

py::dict py_intersect(const PyAccelerator& a, py::handle origins, py::handle directions, py::handle tnear,
                   py::handle tfar) {
    const RayInput in = ray_input(origins, directions, tnear, tfar);
    const auto n = static_cast<py::ssize_t>(in.count);
    py::array_t<float> t(n), u(n), v(n);
    py::array_t<std::int64_t> prim(n);
    const HitOutput out{t.mutable_data(), prim.mutable_data(), u.mutable_data(), v.mutable_data()};
    const std::size_t invalid = without_gil([&] { return intersect(*a.accel, a.team, in, out); });
    if (invalid != kAllValid) throw py::value_error(invalid_ray_message(in, invalid));
    py::dict d;
    d["t"] = t;
    d["prim"] = prim;
    d["u"] = u;
    d["v"] = v;
    return d;
}

py::array_t<bool> py_occluded(const PyAccelerator& a, py::handle origins, py::handle directions, py::handle tnear,
                           py::handle tfar) {
    const RayInput in = ray_input(origins, directions, tnear, tfar);
    py::array_t<bool> out(static_cast<py::ssize_t>(in.count));
    static_assert(sizeof(bool) == sizeof(std::uint8_t));
    auto* bytes = reinterpret_cast<std::uint8_t*>(out.mutable_data());
    const std::size_t invalid = without_gil([&] { return occluded(*a.accel, a.team, in, bytes); });
    if (invalid != kAllValid) throw py::value_error(invalid_ray_message(in, invalid));
    return out;
}

py::tuple vec_tuple(const Vec3& v) { return py::make_tuple(v.x, v.y, v.z); }

// A property's value that must be an object of the class `type` (its Python name): pybind11's own
// refusal was a TypeError naming no property ("(): incompatible function arguments").
template <class T>
T instance_of(py::handle value, const char* name, const char* type) {
    if (!py::isinstance<T>(value))
        throw py::value_error(std::string(name) + " must be a " + type + ", got " + py::repr(value).cast<std::string>());
    return value.cast<T>();
}

// A Vec3 member as a property of three floats, set from any sequence of three finite numbers.
template <class C>
void vec_property(py::class_<C>& cls, const char* name, Vec3 C::*member, const char* doc) {
    cls.def_property(
        name, [member](const C& c) { return vec_tuple(c.*member); },
        [member, name](C& c, py::handle value) { c.*member = vec3_value(value, name); }, doc);
}

std::pair<int, int> image_size(py::handle size) {
    const auto refuse = [&] {
        throw py::value_error("size must be (width, height), got " + py::repr(size).cast<std::string>());
    };
    if (!py::isinstance<py::sequence>(size) || py::isinstance<py::str>(size)) refuse();
    const auto seq = py::reinterpret_borrow<py::sequence>(size);
    if (seq.size() != 2) refuse();
    const unsigned max = static_cast<unsigned>(kMaxImageSide);
    const int w = static_cast<int>(small_count(seq[0], "size[0]", max, 1));
    const int h = static_cast<int>(small_count(seq[1], "size[1]", max, 1));
    try {
        check_image_size(w, h);
    } catch (const Error& e) {
        throw py::value_error(std::string("size: ") + e.what());
    }
    return {w, h};
}

// The image's pixels as an (H, W, 3) float32 array that owns them (no copy).
py::array image_array(Image image) {
    auto* owned = new Image(std::move(image));
    py::capsule free_image(owned, [](void* p) { delete static_cast<Image*>(p); });
    return py::array_t<float>({static_cast<py::ssize_t>(owned->height), static_cast<py::ssize_t>(owned->width),
                               py::ssize_t{3}},
                              reinterpret_cast<const float*>(owned->pixels.data()), free_image);
}

py::array render_scene(py::handle scene_object, py::handle kind, py::handle size, py::handle shading,
                       py::handle threads, py::handle ao_samples, py::handle device) {
    if (!py::isinstance<Scene>(scene_object))
        throw py::value_error("scene must be a cellrt.Scene (cellrt.load_scene), got " +
                              py::repr(scene_object).cast<std::string>());
    AccelConfig config = accel_config(kind, py::str("auto"), threads, py::dict(), device);
    if (!config.traversal.empty()) config.simd = "off";  // a single-ray kernel named, as the CLI's --traversal
    RenderOptions ro;
    ro.threads = config.threads;
    try {
        ro.shading.shading = parse_shading(text(shading, "shading"));
    } catch (const Error& e) {
        throw py::value_error(std::string("shading: ") + e.what());
    }
    ro.shading.ao_samples = static_cast<int>(small_count(ao_samples, "ao_samples", kMaxAoSamples, 1));
    // A copy: the render runs without the GIL, while Python may change the scene's camera.
    const Scene scene = scene_object.cast<const Scene&>();
    std::tie(ro.width, ro.height) = size.is_none() ? std::pair{scene.width, scene.height} : image_size(size);
    Image image = without_gil([&] {
        const std::unique_ptr<Accelerator> accel = make_accelerator(scene.triangles, config);
        return render(scene, *accel, ro);
    });
    return image_array(std::move(image));
}

std::shared_ptr<Scene> load(py::handle path) {
    py::object p;
    try {
        p = call_python(py::module_::import("os").attr("fspath"), py::make_tuple(path));
    } catch (py::error_already_set& e) {
        if (passes_through(e)) throw;
        throw py::value_error("path must be a str or os.PathLike, got " + py::repr(path).cast<std::string>());
    }
    // A str path as the system names the file: the bytes of a name that is not UTF-8 (Linux allows
    // any), which os.listdir hands out as lone surrogates.
    if (!py::isinstance<py::str>(p))
        throw py::value_error("path must be a str or os.PathLike, got " + py::repr(path).cast<std::string>());
    const std::string spec = text(p, "path", true);
    return without_gil([&] { return std::make_shared<Scene>(load_scene(spec)); });
}

py::tuple camera_rays(const Camera& camera, py::handle width, py::handle height) {
    const auto max = static_cast<unsigned>(kMaxImageSide);
    const int w = static_cast<int>(small_count(width, "width", max, 1));
    const int h = static_cast<int>(small_count(height, "height", max, 1));
    const PinholeCamera pinhole(camera, w, h);
    const auto n = static_cast<py::ssize_t>(w) * h;
    py::array_t<float> org({n, py::ssize_t{3}}), dir({n, py::ssize_t{3}});
    float* o = org.mutable_data();
    float* d = dir.mutable_data();
    for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
            const Ray r = pinhole.primary(x, y);
            const std::size_t i = 3 * (static_cast<std::size_t>(y) * w + x);
            o[i] = r.org.x, o[i + 1] = r.org.y, o[i + 2] = r.org.z;
            d[i] = r.dir.x, d[i + 1] = r.dir.y, d[i + 2] = r.dir.z;
        }
    return py::make_tuple(org, dir);
}

}  // namespace
}  // namespace cellrt::python

PYBIND11_MODULE(cellrt, m) {
    using namespace cellrt;
    using namespace cellrt::python;
    m.doc() = "cellrt: ray casting through the SAH kd-tree, BIH, wide BVH and Embree (docs/PYTHON.md)";
    m.attr("__version__") = CELLRT_VERSION_STRING;
    static const py::exception<Error>& error_type = py::register_exception<Error>(m, "Error", PyExc_ValueError);
    error_type.attr("__doc__") = "What the library refuses (a file, a configuration, a camera), with its message naming "
                                 "the file and line, the field or the parameter at fault; a ValueError.";
    // The library's messages name files in the bytes the system gave, which need not be UTF-8: decoded
    // strictly (pybind11's own translator) such a message came out empty. Bytes that are not UTF-8
    // read as \xff escapes. Registered after register_exception's translator, so tried before it.
    py::register_exception_translator([](std::exception_ptr thrown) {
        try {
            if (thrown) std::rethrow_exception(thrown);
        } catch (const Error& e) {
            const std::string_view what = e.what();
            const py::object message = py::reinterpret_steal<py::object>(
                PyUnicode_DecodeUTF8(what.data(), static_cast<Py_ssize_t>(what.size()), "backslashreplace"));
            if (!message) throw py::error_already_set();
            PyErr_SetObject(error_type.ptr(), message.ptr());
        }
    });

    py::class_<TreeReport>(m, "TreeReport", "A tree's build report: its shape, references per triangle, SAH cost")
        .def_readonly("nodes", &TreeReport::nodes, "inner nodes and leaves")
        .def_readonly("inner_nodes", &TreeReport::inner_nodes, "nodes with children")
        .def_readonly("leaves", &TreeReport::leaves, "nodes holding triangle references")
        .def_readonly("empty_leaves", &TreeReport::empty_leaves, "leaves of no triangle")
        .def_readonly("empty_space_nodes", &TreeReport::empty_space_nodes, "BIH: inner nodes cutting off empty space")
        .def_readonly("depth_limit", &TreeReport::depth_limit, "0: none")
        .def_readonly("max_depth", &TreeReport::max_depth, "the deepest leaf's depth (the root: 0)")
        .def_readonly("mean_leaf_depth", &TreeReport::mean_leaf_depth, "over the non-empty leaves")
        .def_readonly("triangles_per_leaf", &TreeReport::triangles_per_leaf, "references per non-empty leaf")
        .def_readonly("references_per_triangle", &TreeReport::references_per_triangle,
                      "leaf references over triangles (above 1 where triangles straddle splits)")
        .def_readonly("sah_cost", &TreeReport::sah_cost, "the expected cost of a ray through the root, in the builder's units");

    py::class_<AccelStats>(m, "AccelStats", "What a built accelerator reports (cellrt/accelerator.hpp)")
        .def_readonly("name", &AccelStats::name, "the kind")
        .def_readonly("traversal", &AccelStats::traversal, "the single-ray kernel, 'packet' (SIMD packets), or Embree's")
        .def_readonly("simd_lanes", &AccelStats::simd_lanes, "rays a SIMD packet traces at once; 0: single rays")
        .def_readonly("build_seconds", &AccelStats::build_seconds, "the build's wall-clock time")
        .def_readonly("memory_bytes", &AccelStats::memory_bytes, "the bytes the structure holds: its nodes, indices and triangle copies of its own; not the triangles "
                       "it reads in place (kd, bih, brute: 0 for brute)")
        .def_readonly("triangles", &AccelStats::triangles, "the triangles it was built over")
        .def_readonly("tree", &AccelStats::tree, "TreeReport (kd-tree, BIH, BVH) or None")
        .def_property_readonly(
            "settings",
            [](const AccelStats& s) {
                py::dict d;
                for (const auto& [k, v] : s.settings) d[py::str(k)] = v;
                return d;
            },
            "the build settings as used, name: value")
        .def_property_readonly("figures", &AccelStats::figures, "the printed report: (name, value) pairs")
        .def("__repr__", [](const AccelStats& s) {
            return "<cellrt.AccelStats " + s.name + ", " + std::to_string(s.triangles) + " triangles, build " +
                   std::to_string(s.build_seconds) + " s, " + std::to_string(s.memory_bytes) + " bytes>";
        });

    py::class_<PyAccelerator> accelerator(m, "Accelerator",
                              "An acceleration structure over triangles. intersect() and occluded() may run at once "
                              "from any number of Python threads; each releases the GIL while it traces.");
    accelerator.def(py::init([](py::handle first, py::handle faces, py::handle kind, py::handle simd, py::handle threads,
                         py::handle params, py::handle device) {
                 const AccelConfig config = accel_config(kind, simd, threads, params, device);
                 return build(faces.is_none() ? triangle_soup(first) : indexed_triangles(first, faces), config);
             }),
             py::arg("vertices"), py::arg("faces") = py::none(), py::kw_only(), py::arg("kind") = py::none(),
             py::arg("simd") = py::none(), py::arg("threads") = 0, py::arg("params") = py::dict(),
             py::arg("device") = "cpu",
             "Accelerator(vertices (N,3), faces (M,3), kind=None, simd=None, threads=0, params={}, device='cpu'), "
             "or Accelerator(triangles (M,3,3), ...). simd None: 'auto', or 'off' where kind names the kd-tree's or "
             "the BIH's single-ray kernel. kind: KIND or KIND:TRAVERSAL (cellrt.kinds()); None: 'auto' "
             "with params packets='bvh' on the CPU, 'kd' on the GPU; device: 'cpu' or 'cuda' (cellrt.device_info()); "
             "the GIL is released during the build.")
        .def("intersect", &py_intersect, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0,
             py::arg("tfar") = std::numeric_limits<double>::infinity(),
             "Closest hits: dict of arrays t (inf on a miss), prim (int64, -1 on a miss), u, v.")
        .def("occluded", &py_occluded, py::arg("origins"), py::arg("directions"), py::arg("tnear") = 0.0,
             py::arg("tfar") = std::numeric_limits<double>::infinity(),
             "Any hit with tnear <= t <= tfar: a bool array.")
        .def_property_readonly("stats", [](const PyAccelerator& a) { return a.accel->stats(); },
                               "AccelStats: build time, memory, the structure's report")
        .def_property_readonly("config", [](const PyAccelerator& a) { return format_accel_config(a.config); },
                               "the configuration built, as one string (e.g. 'auto+auto@packets=bvh')")
        .def_property_readonly("device", [](const PyAccelerator& a) { return a.config.device; },
                               "where it traces: 'cpu' or 'cuda'")
        .def("__repr__", [](const PyAccelerator& a) {
            return "<cellrt.Accelerator " + format_accel_config(a.config) + " on " + a.config.device + ", " +
                   std::to_string(a.triangles.size()) + " triangles>";
        });
    refuse_second_init(accelerator);

    py::class_<Camera> camera(m, "Camera", "A pinhole camera: position, look_at, up, fov_y_deg (full vertical, degrees)");
    camera.def(py::init<>());
    vec_property(camera, "position", &Camera::position, "(x, y, z)");
    vec_property(camera, "look_at", &Camera::look_at, "(x, y, z)");
    vec_property(camera, "up", &Camera::up, "(x, y, z)");
    // Checked when set, as position, look_at and up are, by the rule PinholeCamera applies at render.
    camera.def_property("fov_y_deg", [](const Camera& c) { return c.fov_y_deg; },
                        [](Camera& c, py::handle value) {
                            const auto refuse = [&] {
                                throw py::value_error("fov_y_deg must be a number in (0, 180), got " +
                                                      py::repr(value).cast<std::string>());
                            };
                            if (is_bool(value) || PyNumber_Check(value.ptr()) == 0 ||
                                PyComplex_Check(value.ptr()))
                                refuse();
                            const double d = PyFloat_AsDouble(value.ptr());
                            if (d == -1.0 && PyErr_Occurred()) {
                                py::error_already_set e;
                                if (passes_through(e)) throw e;
                                refuse();
                            }
                            const float f = static_cast<float>(d);
                            if (!(f > 0.f && f < 180.f)) refuse();
                            c.fov_y_deg = f;
                        },
                        "full vertical field of view in degrees, in (0, 180)")
        .def("rays", &camera_rays, py::arg("width"), py::arg("height"),
                 "The primary rays of a width x height image, as the renderer casts them: (origins, directions), "
                 "each (width*height, 3) float32, row-major from the top row.");
    py::class_<PointLight> light(m, "Light", "A point light: position, color");
    light.def(py::init<>());
    vec_property(light, "position", &PointLight::position, "(x, y, z)");
    // Refused when set, as view files refuse it (validate_scene): light is added, never taken away.
    light.def_property(
        "color", [](const PointLight& l) { return vec_tuple(l.color); },
        [](PointLight& l, py::handle value) {
            const Vec3 c = vec3_value(value, "color");
            if (std::string why = light_color_problem(c); !why.empty())
                throw py::value_error("color = " + py::repr(vec_tuple(c)).cast<std::string>() + " " +
                                      why.substr(std::string("the light color ").size()));
            l.color = c;
        },
        "(r, g, b), each from 0 to 1e30");
    refuse_second_init(camera);
    refuse_second_init(light);

    py::class_<Scene, std::shared_ptr<Scene>> scene(m, "Scene", "Triangles, a camera, a point light and an image size");
    scene.def(py::init([](py::handle triangles) {
                 auto s = std::make_shared<Scene>();
                 s->name = "numpy";
                 s->triangles = triangle_soup(triangles);
                 if (s->triangles.empty()) throw py::value_error("triangles must hold at least one triangle");
                 set_default_view(*s);
                 // Not refused: the caller may give the scene a camera and light of its own.
                 if (const std::string why = default_view_problem(*s); !why.empty()) {
                     const std::string warning = "triangles: " + why + "; set scene.camera and scene.light";
                     // Showing a warning runs Python code (warnings._showwarnmsg): interpreter_exit.hpp.
                     const char* const text = warning.c_str();
                     if (unless_the_interpreter_ends([&] { return PyErr_WarnEx(PyExc_RuntimeWarning, text, 1); }) != 0)
                         throw py::error_already_set();
                 }
                 return s;
             }),
             py::arg("triangles"), "Scene(triangles (M,3,3)): framed by the default view of a bare mesh")
        .def_property(
            "name", [](const Scene& s) { return decoded(s.name); },
            [](Scene& s, py::handle value) { s.name = text(value, "name", true); }, "the scene's name (str)")
        .def_property_readonly(
            "triangles",
            [](py::object self) {
                Scene& s = self.cast<Scene&>();
                py::array a(py::dtype::of<float>(), {static_cast<py::ssize_t>(s.triangles.size()), py::ssize_t{3}, py::ssize_t{3}},
                            {py::ssize_t{sizeof(Triangle)}, py::ssize_t{sizeof(Vec3)}, py::ssize_t{sizeof(float)}},
                            reinterpret_cast<const float*>(s.triangles.data()), self);
                a.attr("setflags")(py::arg("write") = false);
                return a;
            },
            "(M, 3, 3) float32, a read-only view of the scene's own triangles")
        .def_property(
            "camera", py::cpp_function([](Scene& s) -> Camera& { return s.camera; }, py::return_value_policy::reference_internal),
            [](Scene& s, py::handle value) { s.camera = instance_of<Camera>(value, "camera", "cellrt.Camera"); },
            "the view, a cellrt.Camera: a live view of the scene's; assigning one copies it in")
        .def_property(
            "light", py::cpp_function([](Scene& s) -> PointLight& { return s.light; }, py::return_value_policy::reference_internal),
            [](Scene& s, py::handle value) { s.light = instance_of<PointLight>(value, "light", "cellrt.Light"); },
            "the point light, a cellrt.Light: a live view of the scene's; assigning one copies it in")
        .def_property(
            "size", [](const Scene& s) { return py::make_tuple(s.width, s.height); },
            [](Scene& s, py::handle size) { std::tie(s.width, s.height) = image_size(size); }, "(width, height)")
        .def("__repr__", [](const Scene& s) {
            return decoded("<cellrt.Scene '" + s.name + "', " + std::to_string(s.triangles.size()) + " triangles, " +
                           std::to_string(s.width) + "x" + std::to_string(s.height) + ">");
        });
    refuse_second_init(scene);
    // pickle's protocols 0 and 1 make an object through pybind11's base type, whose constructor threw a
    // C++ exception that nothing caught: the interpreter aborted (found by review, 2026-12-06). These
    // objects hold C++ state with no Python form, so every protocol, and copy.copy, is a TypeError.
    for (const char* name : {"Accelerator", "Scene", "Camera", "Light", "AccelStats", "TreeReport"}) {
        const py::object cls = m.attr(name);
        cls.attr("__reduce_ex__") = py::cpp_function(
            [](py::handle self, py::handle) -> py::object {
                throw py::type_error(std::string("cannot pickle '") + Py_TYPE(self.ptr())->tp_name + "' object");
            },
            py::name("__reduce_ex__"), py::is_method(cls));
    }

    m.def("load_scene", &load, py::arg("path"),
          "A view file (.json), a mesh (.obj, .ply, .gltf, .glb, and what else the library reads) or builtin:NAME[?tris=N&seed=S]; "
          "cellrt.Error with the library's message naming the file and line.");
    m.def("render", &render_scene, py::arg("scene"), py::kw_only(), py::arg("kind") = py::none(),
          py::arg("size") = py::none(), py::arg("shading") = "direct", py::arg("threads") = 0, py::arg("ao_samples") = 4,
          py::arg("device") = "cpu",
          "The scene rendered as cellrt render renders it: an (H, W, 3) float32 array, the values of its PFM, row 0 "
          "at the top, the same bits with every kind but 'embree' (None: the library's default, as for Accelerator). "
          "device='cuda': every pixel made on the GPU, the same array bit for bit.");
    m.def(
        "device_info",
        [] {
            const DeviceInfo d = cuda_device_info();
            py::dict out;
            out["present"] = d.present;
            out["name"] = d.name;
            out["compute_capability"] = py::make_tuple(d.compute_major, d.compute_minor);
            out["multiprocessors"] = d.multiprocessors;
            out["memory_bytes"] = d.memory_bytes;
            out["reason"] = d.reason;
            return out;
        },
        "The CUDA device device='cuda' would use, as cellrt info --device cuda names it: a dict with present, name, "
        "compute_capability, multiprocessors, memory_bytes, and the reason when there is none.");
    m.def("kinds", &accelerator_kinds, "The accelerator kinds of this build.");

    // For the tests and the benchmark.
    m.def("_reads_in_place", [](py::handle array) { return float_rows(array, "array", 3).borrowed; });
    m.def(
        "_native_intersect_seconds",
        [](const PyAccelerator& a, py::handle origins, py::handle directions, int repeats, py::handle clock) {
            const std::string which = text(clock, "clock");
            if (which != "wall" && which != "cpu") throw py::value_error("clock must be 'wall' or 'cpu'");
            const RayInput in = ray_input(origins, directions, py::float_(0.0),
                                          py::float_(std::numeric_limits<double>::infinity()));
            return without_gil([&] { return native_intersect_seconds(*a.accel, a.team, in, repeats, which == "cpu"); });
        },
        py::arg("accelerator"), py::arg("origins"), py::arg("directions"), py::arg("repeats"), py::arg("clock") = "wall");
}
