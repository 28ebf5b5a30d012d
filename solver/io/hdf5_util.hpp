// Internal helpers of the io module around the HDF5 C++ API (not part of the public API).
//
// The HDF5 C++ API throws H5::Exception, which does not derive from std::exception; every
// public entry point of io converts it into core::Error through `translate_h5_errors`, so
// callers only ever see caplab's error types. Strings are written as variable-length UTF-8
// (h5py returns them as `str`); JSON values that are not strings are written as their dump.
#pragma once

#include <H5Cpp.h>

#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "core/error.hpp"

namespace caplab::io::detail {

/// Runs f(); an H5::Exception escaping it becomes a core::Error naming `what` and the file.
template <class F>
decltype(auto) translate_h5_errors(const std::string& what, const std::filesystem::path& file, F&& f) {
  try {
    return std::forward<F>(f)();
  } catch (const H5::Exception& e) {
    throw core::Error("io: HDF5 error while " + what + " (" + file.string() + "): " + e.getFuncName() + ": " +
                      e.getDetailMsg());
  }
}

/// True for names usable as HDF5 link names and inside XML attributes unescaped:
/// non-empty, [A-Za-z0-9_.+-] only, not starting with '.'.
bool is_valid_name(const std::string& name);

/// Throws core::Error unless is_valid_name(name); `kind` says what the name is for.
void check_name(const std::string& name, const std::string& kind);

/// Writes (or replaces) a scalar variable-length UTF-8 string attribute on `obj`.
void write_string_attribute(H5::H5Object& obj, const std::string& name, const std::string& value);

/// Reads a string attribute (variable or fixed length).
std::string read_string_attribute(const H5::H5Object& obj, const std::string& name);

/// Writes every member of a JSON object as a string attribute (strings as is, others as JSON text).
void write_json_attributes(H5::H5Object& obj, const nlohmann::json& attributes);

/// Writes a scalar or 1-D double attribute.
void write_double_attribute(H5::H5Object& obj, const std::string& name, const std::vector<double>& values);

/// Writes a scalar or 1-D int attribute.
void write_int_attribute(H5::H5Object& obj, const std::string& name, const std::vector<int>& values);

/// Creates a contiguous dataset of doubles with the given shape and writes `data` (row-major).
void write_dataset(H5::Group& group, const std::string& name, const std::vector<hsize_t>& shape,
                   const double* data);

/// Creates a contiguous dataset of 32-bit ints with the given shape and writes `data` (row-major).
void write_dataset(H5::Group& group, const std::string& name, const std::vector<hsize_t>& shape,
                   const int* data);

}  // namespace caplab::io::detail
