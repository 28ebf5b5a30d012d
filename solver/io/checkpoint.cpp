#include "io/checkpoint.hpp"

#include <hdf5.h>

#include <fmt/format.h>

#include "core/error.hpp"

namespace caplab::io {

namespace fs = std::filesystem;

namespace {

hid_t native_type(detail::ValueType t) {
  switch (t) {
    case detail::ValueType::f64: return H5T_NATIVE_DOUBLE;
    case detail::ValueType::f32: return H5T_NATIVE_FLOAT;
    case detail::ValueType::i64: return H5T_NATIVE_INT64;
    case detail::ValueType::i32: return H5T_NATIVE_INT32;
    case detail::ValueType::u32: return H5T_NATIVE_UINT32;
    case detail::ValueType::u8: return H5T_NATIVE_UINT8;
  }
  return H5T_NATIVE_UINT8;
}

const char* type_name(detail::ValueType t) {
  constexpr const char* names[] = {"float64", "float32", "int64", "int32", "uint32", "uint8"};
  return names[static_cast<int>(t)];
}

/// Closes an HDF5 identifier when it goes out of scope.
struct Handle {
  hid_t id;
  herr_t (*close)(hid_t);
  Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~Handle() {
    if (id >= 0) close(id);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
};

/// HDF5 prints its error stack by default; caplab reports errors itself.
void silence_hdf5() { H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr); }

}  // namespace

struct CheckpointWriter::Impl {
  fs::path file;
  hid_t h5 = -1;
  hid_t lcpl = -1;
};

CheckpointWriter::CheckpointWriter(fs::path file) : impl_(std::make_unique<Impl>()) {
  silence_hdf5();
  impl_->file = std::move(file);
  impl_->h5 = H5Fcreate(impl_->file.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
  if (impl_->h5 < 0) throw core::Error("io: cannot create the checkpoint file '" + impl_->file.string() + "'");
  impl_->lcpl = H5Pcreate(H5P_LINK_CREATE);
  H5Pset_create_intermediate_group(impl_->lcpl, 1);
}

CheckpointWriter::~CheckpointWriter() {
  try {
    close();
  } catch (...) {
  }
}

void CheckpointWriter::put(const std::string& name, const void* data, std::size_t count, detail::ValueType type) {
  CAPLAB_CHECK(impl_->h5 >= 0, "io: checkpoint '" + impl_->file.string() + "' is closed");
  const hsize_t dims = count;
  Handle space(H5Screate_simple(1, &dims, nullptr), H5Sclose);
  Handle ds(H5Dcreate2(impl_->h5, name.c_str(), native_type(type), space.id, impl_->lcpl, H5P_DEFAULT, H5P_DEFAULT),
            H5Dclose);
  if (ds.id < 0 || (count > 0 && H5Dwrite(ds.id, native_type(type), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0))
    throw core::Error(fmt::format("io: cannot write '{}' ({} values) into the checkpoint '{}' (disk full?)", name,
                                  count, impl_->file.string()));
}

void CheckpointWriter::operator()(const std::string& name, bool& value) {
  std::uint8_t v = value ? 1 : 0;
  (*this)(name, v);
}

void CheckpointWriter::operator()(const std::string& name, std::string& text) {
  put(name, text.data(), text.size(), detail::ValueType::u8);
}

void CheckpointWriter::close() {
  if (impl_->lcpl >= 0) H5Pclose(impl_->lcpl), impl_->lcpl = -1;
  if (impl_->h5 < 0) return;
  const bool ok = H5Fflush(impl_->h5, H5F_SCOPE_LOCAL) >= 0;
  const bool closed = H5Fclose(impl_->h5) >= 0;
  impl_->h5 = -1;
  if (!ok || !closed) throw core::Error("io: cannot close the checkpoint file '" + impl_->file.string() + "' (disk full?)");
}

std::uintmax_t CheckpointWriter::file_bytes() const {
  std::error_code ec;
  const auto n = fs::file_size(impl_->file, ec);
  return ec ? 0 : n;
}

struct CheckpointReader::Impl {
  fs::path file;
  hid_t h5 = -1;
};

CheckpointReader::CheckpointReader(fs::path file) : impl_(std::make_unique<Impl>()) {
  silence_hdf5();
  impl_->file = std::move(file);
  impl_->h5 = H5Fopen(impl_->file.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT);
  if (impl_->h5 < 0)
    throw core::Error("io: cannot open the checkpoint '" + impl_->file.string() + "' (missing or damaged)");
}

CheckpointReader::~CheckpointReader() {
  if (impl_->h5 >= 0) H5Fclose(impl_->h5);
}

const fs::path& CheckpointReader::file() const { return impl_->file; }

bool CheckpointReader::contains(const std::string& name) const {
  // H5Lexists needs every intermediate group to exist: check the path one level at a time.
  std::size_t pos = 0;
  while (true) {
    const std::size_t next = name.find('/', pos);
    const std::string prefix = name.substr(0, next);
    if (H5Lexists(impl_->h5, prefix.c_str(), H5P_DEFAULT) <= 0) return false;
    if (next == std::string::npos) return true;
    pos = next + 1;
  }
}

std::size_t CheckpointReader::size_of(const std::string& name) const {
  if (!contains(name))
    throw core::Error(fmt::format("io: the checkpoint '{}' has no entry '{}': it was written by another case or "
                                  "build of caplab",
                                  impl_->file.string(), name));
  Handle ds(H5Dopen2(impl_->h5, name.c_str(), H5P_DEFAULT), H5Dclose);
  Handle space(H5Dget_space(ds.id), H5Sclose);
  return static_cast<std::size_t>(H5Sget_simple_extent_npoints(space.id));
}

void CheckpointReader::get(const std::string& name, void* data, std::size_t count, detail::ValueType type) {
  const std::size_t stored = size_of(name);
  Handle ds(H5Dopen2(impl_->h5, name.c_str(), H5P_DEFAULT), H5Dclose);
  Handle ftype(H5Dget_type(ds.id), H5Tclose);
  if (H5Tequal(ftype.id, native_type(type)) <= 0 || stored != count)
    throw core::Error(fmt::format("io: the checkpoint entry '{}' in '{}' holds {} values of another type or size than "
                                  "the {} {} this run expects: it was written by another case or build of caplab",
                                  name, impl_->file.string(), stored, count, type_name(type)));
  if (count > 0 && H5Dread(ds.id, native_type(type), H5S_ALL, H5S_ALL, H5P_DEFAULT, data) < 0)
    throw core::Error(fmt::format("io: cannot read '{}' from the checkpoint '{}' (damaged file)", name,
                                  impl_->file.string()));
}

void CheckpointReader::operator()(const std::string& name, bool& value) {
  std::uint8_t v = 0;
  (*this)(name, v);
  value = v != 0;
}

void CheckpointReader::operator()(const std::string& name, std::string& text) {
  text.resize(size_of(name));
  get(name, text.data(), text.size(), detail::ValueType::u8);
}

}  // namespace caplab::io
