// A bound class's objects reach its methods only once made: pybind11 hands
// a method of an object whose __init__ never ran (World.__new__(World),
// Robots.__new__(Robots)) uninitialised memory it allocated on the spot,
// and the method crashed the interpreter. The caster of such a class
// (specialised as below, before any use) raises TypeError instead.
//
//   namespace pybind11::detail {
//   template <>
//   class type_caster<swarmsim::python::PyWorld>
//       : public swarmsim::python::InitializedCaster<swarmsim::python::PyWorld> {};
//   }
#pragma once

#include <pybind11/pybind11.h>

#include <string>

namespace swarmsim::python {

template <typename T>
class InitializedCaster : public pybind11::detail::type_caster_base<T> {
 public:
  bool load(pybind11::handle src, bool convert) {
    if (!pybind11::detail::type_caster_base<T>::load(src, convert)) return false;
    // An instance of the class (or of a Python subclass) whose holder was
    // never made: raised before the method runs.
    auto* instance = reinterpret_cast<pybind11::detail::instance*>(src.ptr());
    const pybind11::detail::value_and_holder v_h =
        instance->get_value_and_holder(nullptr, /*throw_if_missing=*/false);
    if (!v_h || !v_h.holder_constructed()) {
      const std::string name = pybind11::str(pybind11::type::handle_of(src).attr("__name__"));
      throw pybind11::type_error(name + " object was made by " + name + ".__new__ without " + name +
                                 ".__init__: it holds nothing (make one with " + name + "(...))");
    }
    return true;
  }
};

}  // namespace swarmsim::python
