#include "rwcalc/error.hpp"

#include <fmt/format.h>

#include <utility>

namespace rwcalc {

namespace {
std::string format_input_error(const std::string& file, std::size_t line, const std::string& message) {
  return line > 0 ? fmt::format("{}:{}: {}", file, line, message) : fmt::format("{}: {}", file, message);
}
}  // namespace

InputError::InputError(std::string file, std::size_t line, std::string message)
    : Error(format_input_error(file, line, message), ExitCode::BadInput),
      file_(std::move(file)),
      line_(line),
      message_(std::move(message)) {}

}  // namespace rwcalc
