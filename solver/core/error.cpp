#include "core/error.hpp"

#include <fmt/format.h>

namespace caplab::core {

InputError::InputError(std::string file, std::string json_path, std::string value, std::string expected)
    : Error(fmt::format("{}: at {}: got {}; expected {}", file.empty() ? "<input>" : file,
                        json_path.empty() ? "/" : json_path, value, expected)),
      file_(std::move(file)),
      json_path_(std::move(json_path)),
      value_(std::move(value)),
      expected_(std::move(expected)) {}

InputError::InputError(const std::string& message) : Error(message) {}

NumericalError::NumericalError(long step, std::string where, std::string quantity, std::string cause)
    : Error(fmt::format("numerical instability at step {} ({}): {}. Likely cause: {}", step, where, quantity,
                        cause)),
      step_(step),
      where_(std::move(where)),
      quantity_(std::move(quantity)),
      cause_(std::move(cause)) {}

void check_failed(const char* condition, const char* file, int line, const std::string& message) {
  throw Error(fmt::format("{} [check `{}` failed at {}:{}]", message, condition, file, line));
}

}  // namespace caplab::core
