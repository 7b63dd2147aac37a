#include "rwcalc/error.hpp"

#include <fmt/format.h>

#include <utility>

namespace rwcalc {

InputError::InputError(std::string file, std::size_t line, std::string message)
    : Error(line > 0 ? fmt::format("{}:{}: {}", file, line, message) : fmt::format("{}: {}", file, message),
            ExitCode::BadInput),
      file_(std::move(file)),
      line_(line),
      message_(std::move(message)) {}

}  // namespace rwcalc
