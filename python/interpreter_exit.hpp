// Threads at the interpreter's exit. Python before 3.14 ends a thread that takes the GIL while the
// interpreter finalizes (a daemon thread still running) by pthread_exit, whose forced unwinding runs
// the destructors of every C++ frame it passes. Those of the module's frames give Python objects back
// (Py_DECREF) without the GIL, racing the finalizing collector: a segmentation fault, or
// std::terminate out of a noexcept destructor. A thread takes the GIL back where the module released
// it (PyEval_RestoreThread), and wherever Python code runs, which may hand the GIL to another thread
// and wait for it back: numpy.require converting every ray bound crashed one exit in a hundred under
// load (Python.test_accelerator, found on a loaded machine, 2026-12-07). Such calls go through here: the
// unwinding is caught where it leaves Python, before any C++ frame, and the thread waits there,
// holding no GIL, for the process to end, as Python 3.14 makes such threads do itself. A thread that
// comes back before finalization goes on as usual.
#pragma once

#include <pybind11/pybind11.h>

#ifdef __GLIBCXX__
#include <cxxabi.h>
#endif

#include <chrono>
#include <thread>

namespace cellrt::python {

namespace py = pybind11;

// f(), a call into the interpreter's C API that holds no C++ object of its own (only pointers), or
// never returns if the interpreter ends the thread in it.
template <class F>
auto unless_the_interpreter_ends(F&& f) -> decltype(f()) {
#ifdef __GLIBCXX__
    try {
        return f();
    } catch (abi::__forced_unwind&) {
        for (;;) std::this_thread::sleep_for(std::chrono::hours(24));
    }
#else
    return f();
#endif
}

// callable(*args, **kwargs), which may run Python code: pybind11's own call, but safe at exit. No
// kwargs: a null handle, as PyObject_Call takes it.
inline py::object call_python(py::handle callable, const py::tuple& args, py::handle kwargs = py::handle()) {
    PyObject* const result =
        unless_the_interpreter_ends([&] { return PyObject_Call(callable.ptr(), args.ptr(), kwargs.ptr()); });
    if (!result) throw py::error_already_set();
    return py::reinterpret_steal<py::object>(result);
}

}  // namespace cellrt::python
