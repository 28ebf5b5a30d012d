// Time series of a run (series.h5, DESIGN.md section 6).
//
// Layout: one 1-D, extendible, chunked float64 dataset per column under the root group,
// each with string attributes "unit" and "definition"; the root group carries the caller's
// attributes (e.g. the case id) as strings and "columns", the column names in order as a
// JSON array. By convention the first column is "t". Rows are buffered in memory and written
// every `flush_every` rows and on close(), each write followed by an HDF5 flush, so a killed
// run keeps everything up to its last flush.
//
// Not thread-safe (serial HDF5): one writer is driven from one thread.
#pragma once

#include <cstddef>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <vector>

namespace caplab::io {

/// One column of a time series: name (an HDF5 link name: letters, digits, '_', '.', '+', '-'),
/// unit (e.g. "s", "1", "lattice") and a one-line definition.
struct SeriesColumn {
  std::string name;
  std::string unit;
  std::string definition;
};

/// Writer of series.h5 (see the file header for the layout).
class SeriesWriter {
 public:
  /// Creates (truncates) `file` with one dataset per column and the root `attributes`
  /// (a JSON object; non-string values are stored as their JSON text; the key "columns" is
  /// reserved). Rows are written every `flush_every` rows (>= 1).
  SeriesWriter(std::filesystem::path file, std::vector<SeriesColumn> columns,
               const nlohmann::json& attributes = nlohmann::json::object(), std::size_t flush_every = 100);
  /// Closes the file if close() was not called; errors are swallowed here, so call close().
  ~SeriesWriter();
  SeriesWriter(SeriesWriter&&) noexcept;
  SeriesWriter& operator=(SeriesWriter&&) noexcept;
  SeriesWriter(const SeriesWriter&) = delete;
  SeriesWriter& operator=(const SeriesWriter&) = delete;

  /// Appends one row: one value per column, in column order.
  void append(std::span<const double> row);
  /// Writes the buffered rows and flushes the file.
  void flush();
  /// Flushes and closes the file; further appends throw. Idempotent.
  void close();

  /// Rows appended so far (written or buffered).
  std::size_t rows() const;
  const std::vector<SeriesColumn>& columns() const;
  const std::filesystem::path& file() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads every column of a series file written by SeriesWriter: name -> values.
std::map<std::string, std::vector<double>> read_series(const std::filesystem::path& file);

/// Reads the column descriptions (name, unit, definition) of a series file, in column order.
std::vector<SeriesColumn> read_series_columns(const std::filesystem::path& file);

}  // namespace caplab::io
