#include "io/hdf5_util.hpp"

#include <algorithm>

namespace caplab::io::detail {

bool is_valid_name(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '.' || c == '-' || c == '+';
  });
}

void check_name(const std::string& name, const std::string& kind) {
  if (!is_valid_name(name))
    throw core::Error("io: invalid " + kind + " name '" + name +
                      "': use letters, digits, '_', '.', '+', '-' (not starting with '.')");
}

void write_string_attribute(H5::H5Object& obj, const std::string& name, const std::string& value) {
  H5::StrType type(H5::PredType::C_S1, H5T_VARIABLE);
  type.setCset(H5T_CSET_UTF8);
  if (obj.attrExists(name)) obj.removeAttr(name);
  H5::Attribute attr = obj.createAttribute(name, type, H5::DataSpace(H5S_SCALAR));
  attr.write(type, value);
}

std::string read_string_attribute(const H5::H5Object& obj, const std::string& name) {
  if (!obj.attrExists(name)) throw core::Error("io: HDF5 attribute '" + name + "' is missing");
  H5::Attribute attr = obj.openAttribute(name);
  std::string value;
  attr.read(attr.getStrType(), value);
  return value;
}

void write_json_attributes(H5::H5Object& obj, const nlohmann::json& attributes) {
  if (attributes.is_null()) return;
  CAPLAB_CHECK(attributes.is_object(), "io: file attributes must be a JSON object");
  for (const auto& [key, value] : attributes.items())
    write_string_attribute(obj, key, value.is_string() ? value.get<std::string>() : value.dump());
}

namespace {

template <class T>
void write_numeric_attribute(H5::H5Object& obj, const std::string& name, const std::vector<T>& values,
                             const H5::PredType& type) {
  if (obj.attrExists(name)) obj.removeAttr(name);
  const hsize_t n = values.size();
  H5::DataSpace space = values.size() == 1 ? H5::DataSpace(H5S_SCALAR) : H5::DataSpace(1, &n);
  H5::Attribute attr = obj.createAttribute(name, type, space);
  attr.write(type, values.data());
}

template <class T>
void write_numeric_dataset(H5::Group& group, const std::string& name, const std::vector<hsize_t>& shape,
                           const T* data, const H5::PredType& mem_type, const H5::PredType& file_type) {
  H5::DataSpace space(static_cast<int>(shape.size()), shape.data());
  H5::DataSet ds = group.createDataSet(name, file_type, space);
  ds.write(data, mem_type);
}

}  // namespace

void write_double_attribute(H5::H5Object& obj, const std::string& name, const std::vector<double>& values) {
  write_numeric_attribute(obj, name, values, H5::PredType::NATIVE_DOUBLE);
}

void write_int_attribute(H5::H5Object& obj, const std::string& name, const std::vector<int>& values) {
  write_numeric_attribute(obj, name, values, H5::PredType::NATIVE_INT);
}

void write_dataset(H5::Group& group, const std::string& name, const std::vector<hsize_t>& shape,
                   const double* data) {
  write_numeric_dataset(group, name, shape, data, H5::PredType::NATIVE_DOUBLE, H5::PredType::IEEE_F64LE);
}

void write_dataset(H5::Group& group, const std::string& name, const std::vector<hsize_t>& shape,
                   const int* data) {
  write_numeric_dataset(group, name, shape, data, H5::PredType::NATIVE_INT, H5::PredType::STD_I32LE);
}

}  // namespace caplab::io::detail
