// Checkpoints of a run (checkpoint.h5): the whole evolving state of a scene, so that
// `caplab run --resume` continues an interrupted run bit for bit.
//
// One archive interface serves saving and loading. A class with state writes one member
//   template <class Archive> void checkpoint(Archive& ar, const std::string& prefix);
// that names each piece of its state:
//   ar(name, std::span<T>)        an array whose size the class knows (sizes must match on load)
//   ar(name, std::vector<T>&)     an array that grows (resized on load)
//   ar(name, T&)                  a scalar (arithmetic or bool)
//   ar(name, std::string&)        text (e.g. JSON)
// CheckpointWriter stores what it is given, CheckpointReader overwrites it with what is stored,
// so what is saved and what is restored can never drift apart. T is double, float, int64,
// int32, uint32 or uint8; names are '/'-separated paths ("fluid/block0/pop_a").
//
// File: one flat dataset per name in a single HDF5 file, written under a temporary name and
// renamed into place by the caller (RunDirectory::commit_file), so a checkpoint is either
// complete or absent. A reader refuses a name that is missing or has another type or size:
// the checkpoint was written by another case or build.
//
// Not thread-safe (serial HDF5).
#pragma once

#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

namespace caplab::io {

namespace detail {
/// The element types a checkpoint stores.
template <class T>
concept CheckpointValue = std::is_same_v<T, double> || std::is_same_v<T, float> || std::is_same_v<T, std::int64_t> ||
                          std::is_same_v<T, std::int32_t> || std::is_same_v<T, std::uint32_t> ||
                          std::is_same_v<T, std::uint8_t>;
enum class ValueType { f64, f32, i64, i32, u32, u8 };
template <class T>
constexpr ValueType value_type() {
  if constexpr (std::is_same_v<T, double>) return ValueType::f64;
  if constexpr (std::is_same_v<T, float>) return ValueType::f32;
  if constexpr (std::is_same_v<T, std::int64_t>) return ValueType::i64;
  if constexpr (std::is_same_v<T, std::int32_t>) return ValueType::i32;
  if constexpr (std::is_same_v<T, std::uint32_t>) return ValueType::u32;
  return ValueType::u8;
}
}  // namespace detail

/// Writes a checkpoint to `file` (created or truncated); close() makes it complete.
class CheckpointWriter {
 public:
  static constexpr bool loading = false;
  explicit CheckpointWriter(std::filesystem::path file);
  ~CheckpointWriter();
  CheckpointWriter(const CheckpointWriter&) = delete;
  CheckpointWriter& operator=(const CheckpointWriter&) = delete;

  template <detail::CheckpointValue T>
  void operator()(const std::string& name, std::span<T> data) {
    put(name, data.data(), data.size(), detail::value_type<T>());
  }
  template <detail::CheckpointValue T>
  void operator()(const std::string& name, std::vector<T>& data) {
    put(name, data.data(), data.size(), detail::value_type<T>());
  }
  template <detail::CheckpointValue T>
  void operator()(const std::string& name, T& value) {
    put(name, &value, 1, detail::value_type<T>());
  }
  void operator()(const std::string& name, bool& value);
  void operator()(const std::string& name, std::string& text);

  /// Flushes and closes the file (idempotent). Bytes written are then file_bytes().
  void close();
  std::uintmax_t file_bytes() const;

 private:
  void put(const std::string& name, const void* data, std::size_t count, detail::ValueType type);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// Reads a checkpoint written by CheckpointWriter. Throws core::Error naming the file and the
/// entry when an entry is missing or has another type or size.
class CheckpointReader {
 public:
  static constexpr bool loading = true;
  explicit CheckpointReader(std::filesystem::path file);
  ~CheckpointReader();
  CheckpointReader(const CheckpointReader&) = delete;
  CheckpointReader& operator=(const CheckpointReader&) = delete;

  template <detail::CheckpointValue T>
  void operator()(const std::string& name, std::span<T> data) {
    get(name, data.data(), data.size(), detail::value_type<T>());
  }
  template <detail::CheckpointValue T>
  void operator()(const std::string& name, std::vector<T>& data) {
    data.resize(size_of(name));
    get(name, data.data(), data.size(), detail::value_type<T>());
  }
  template <detail::CheckpointValue T>
  void operator()(const std::string& name, T& value) {
    get(name, &value, 1, detail::value_type<T>());
  }
  void operator()(const std::string& name, bool& value);
  void operator()(const std::string& name, std::string& text);

  /// Whether the checkpoint holds `name`.
  bool contains(const std::string& name) const;
  const std::filesystem::path& file() const;

 private:
  std::size_t size_of(const std::string& name) const;
  void get(const std::string& name, void* data, std::size_t count, detail::ValueType type);
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace caplab::io
