#include "io/series_writer.hpp"

#include <H5Cpp.h>

#include <optional>
#include <set>

#include "core/error.hpp"
#include "io/hdf5_util.hpp"

namespace caplab::io {

namespace fs = std::filesystem;

namespace {

constexpr hsize_t kChunkRows = 1024;
constexpr const char* kColumnsAttribute = "columns";

}  // namespace

struct SeriesWriter::Impl {
  fs::path file;
  std::vector<SeriesColumn> columns;
  std::size_t flush_every = 100;
  std::optional<H5::H5File> h5;  // optional: H5File's copy assignment is deprecated
  std::vector<H5::DataSet> datasets;
  std::vector<std::vector<double>> buffer;  // per column, the rows not yet written
  std::size_t rows_written = 0;
  bool open = false;

  std::size_t rows_buffered() const { return buffer.empty() ? 0 : buffer.front().size(); }

  void write_buffer() {
    const std::size_t n = rows_buffered();
    if (n == 0) return;
    const hsize_t offset = rows_written;
    const hsize_t count = n;
    const hsize_t new_size = offset + count;
    for (std::size_t c = 0; c < columns.size(); ++c) {
      H5::DataSet& ds = datasets[c];
      ds.extend(&new_size);
      H5::DataSpace file_space = ds.getSpace();
      file_space.selectHyperslab(H5S_SELECT_SET, &count, &offset);
      H5::DataSpace mem_space(1, &count);
      ds.write(buffer[c].data(), H5::PredType::NATIVE_DOUBLE, mem_space, file_space);
      buffer[c].clear();
    }
    rows_written += n;
    h5->flush(H5F_SCOPE_LOCAL);
  }
};

SeriesWriter::SeriesWriter(fs::path file, std::vector<SeriesColumn> columns, const nlohmann::json& attributes,
                           std::size_t flush_every)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.file = std::move(file);
  m.columns = std::move(columns);
  m.flush_every = flush_every;
  CAPLAB_CHECK(flush_every >= 1, "io: SeriesWriter needs flush_every >= 1");
  CAPLAB_CHECK(!m.columns.empty(), "io: a series needs at least one column");
  std::set<std::string> names;
  nlohmann::json column_names = nlohmann::json::array();
  for (const SeriesColumn& c : m.columns) {
    detail::check_name(c.name, "series column");
    if (!names.insert(c.name).second) throw core::Error("io: series column '" + c.name + "' appears twice");
    column_names.push_back(c.name);
  }
  CAPLAB_CHECK(attributes.is_null() || attributes.is_object(), "io: series attributes must be a JSON object");
  if (attributes.is_object() && attributes.contains(kColumnsAttribute))
    throw core::Error("io: the series attribute 'columns' is reserved (it lists the columns)");

  detail::translate_h5_errors("creating the series file", m.file, [&] {
    m.h5.emplace(m.file.string(), H5F_ACC_TRUNC);
    detail::write_json_attributes(*m.h5, attributes);
    detail::write_string_attribute(*m.h5, kColumnsAttribute, column_names.dump());
    const hsize_t initial = 0, max_size = H5S_UNLIMITED, chunk = kChunkRows;
    H5::DSetCreatPropList props;
    props.setChunk(1, &chunk);
    for (const SeriesColumn& c : m.columns) {
      H5::DataSpace space(1, &initial, &max_size);
      H5::DataSet ds = m.h5->createDataSet(c.name, H5::PredType::IEEE_F64LE, space, props);
      detail::write_string_attribute(ds, "unit", c.unit);
      detail::write_string_attribute(ds, "definition", c.definition);
      m.datasets.push_back(ds);
    }
    m.h5->flush(H5F_SCOPE_LOCAL);
  });
  m.buffer.resize(m.columns.size());
  for (auto& b : m.buffer) b.reserve(m.flush_every);
  m.open = true;
}

SeriesWriter::~SeriesWriter() {
  if (!impl_) return;
  try {
    close();
  } catch (...) {  // a destructor must not throw; close() explicitly to see the error
  }
}

SeriesWriter::SeriesWriter(SeriesWriter&&) noexcept = default;
SeriesWriter& SeriesWriter::operator=(SeriesWriter&&) noexcept = default;

void SeriesWriter::append(std::span<const double> row) {
  Impl& m = *impl_;
  if (!m.open) throw core::Error("io: append to the closed series file '" + m.file.string() + "'");
  if (row.size() != m.columns.size())
    throw core::Error("io: series row has " + std::to_string(row.size()) + " values, expected " +
                      std::to_string(m.columns.size()) + " (one per column)");
  for (std::size_t c = 0; c < row.size(); ++c) m.buffer[c].push_back(row[c]);
  if (m.rows_buffered() >= m.flush_every) flush();
}

void SeriesWriter::flush() {
  Impl& m = *impl_;
  if (!m.open) return;
  detail::translate_h5_errors("writing the series file", m.file, [&] { m.write_buffer(); });
}

void SeriesWriter::close() {
  Impl& m = *impl_;
  if (!m.open) return;
  flush();
  detail::translate_h5_errors("closing the series file", m.file, [&] {
    m.datasets.clear();
    m.h5->close();
    m.h5.reset();
  });
  m.open = false;
}

std::size_t SeriesWriter::rows() const { return impl_->rows_written + impl_->rows_buffered(); }
const std::vector<SeriesColumn>& SeriesWriter::columns() const { return impl_->columns; }
const fs::path& SeriesWriter::file() const { return impl_->file; }

namespace {

void check_readable(const fs::path& file) {
  std::error_code ec;
  if (!fs::is_regular_file(file, ec))
    throw core::InputError("series file '" + file.string() + "' does not exist (did the run finish?)");
}

/// Column names in stored order: the "columns" attribute, else the root datasets by name.
std::vector<std::string> column_names(const H5::H5File& h5) {
  std::vector<std::string> names;
  if (h5.attrExists(kColumnsAttribute)) {
    const auto list = nlohmann::json::parse(detail::read_string_attribute(h5, kColumnsAttribute));
    for (const auto& n : list) names.push_back(n.get<std::string>());
    return names;
  }
  for (hsize_t i = 0; i < h5.getNumObjs(); ++i)
    if (h5.getObjTypeByIdx(i) == H5G_DATASET) names.push_back(h5.getObjnameByIdx(i));
  return names;
}

}  // namespace

std::map<std::string, std::vector<double>> read_series(const fs::path& file) {
  check_readable(file);
  return detail::translate_h5_errors("reading the series file", file, [&] {
    H5::H5File h5(file.string(), H5F_ACC_RDONLY);
    std::map<std::string, std::vector<double>> series;
    for (const std::string& name : column_names(h5)) {
      H5::DataSet ds = h5.openDataSet(name);
      H5::DataSpace space = ds.getSpace();
      if (space.getSimpleExtentNdims() != 1)
        throw core::Error("io: series dataset '" + name + "' in '" + file.string() + "' is not 1-D");
      hsize_t n = 0;
      space.getSimpleExtentDims(&n);
      std::vector<double> values(n);
      if (n > 0) ds.read(values.data(), H5::PredType::NATIVE_DOUBLE);
      series.emplace(name, std::move(values));
    }
    return series;
  });
}

std::vector<SeriesColumn> read_series_columns(const fs::path& file) {
  check_readable(file);
  return detail::translate_h5_errors("reading the series file", file, [&] {
    H5::H5File h5(file.string(), H5F_ACC_RDONLY);
    std::vector<SeriesColumn> columns;
    for (const std::string& name : column_names(h5)) {
      H5::DataSet ds = h5.openDataSet(name);
      SeriesColumn c{name, "", ""};
      if (ds.attrExists("unit")) c.unit = detail::read_string_attribute(ds, "unit");
      if (ds.attrExists("definition")) c.definition = detail::read_string_attribute(ds, "definition");
      columns.push_back(std::move(c));
    }
    return columns;
  });
}

}  // namespace caplab::io
