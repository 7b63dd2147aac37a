#include "rwcalc/error.hpp"

#include <utility>

namespace rwcalc {

namespace {
std::string format_input_error(const std::string& file, std::size_t line, const std::string& message) {
  std::string s = file;
  if (line > 0) s += ":" + std::to_string(line);
  s += ": " + message;
  return s;
}
}  // namespace

InputError::InputError(std::string file, std::size_t line, std::string message)
    : Error(format_input_error(file, line, message), ExitCode::BadInput),
      file_(std::move(file)),
      line_(line),
      message_(std::move(message)) {}

}  // namespace rwcalc
