#pragma once
/// @file error.hpp
/// Error types and the exit status each maps to. The library throws; cli::run catches at one
/// place and prints the message. Exit statuses: 0 success; 1 the analysis cannot be done on valid
/// input; 2 bad input or usage; 3 an output could not be written.
#include <cstddef>
#include <stdexcept>
#include <string>

namespace rwcalc {

enum class ExitCode : int { Ok = 0, AnalysisFailed = 1, BadInput = 2, OutputFailed = 3 };

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what, ExitCode code) : std::runtime_error(what), code_(code) {}
  [[nodiscard]] ExitCode code() const noexcept { return code_; }

 private:
  ExitCode code_;
};

/// Bad input data: what() reads "FILE:LINE: MESSAGE" (or "FILE: MESSAGE" when line is 0).
class InputError : public Error {
 public:
  InputError(std::string file, std::size_t line, std::string message);
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  [[nodiscard]] std::size_t line() const noexcept { return line_; }
  [[nodiscard]] const std::string& message() const noexcept { return message_; }

 private:
  std::string file_;
  std::size_t line_;
  std::string message_;
};

/// Invalid option value or combination (exit 2).
class UsageError : public Error {
 public:
  explicit UsageError(const std::string& what) : Error(what, ExitCode::BadInput) {}
};

/// Valid input on which the requested analysis cannot be carried out (exit 1).
class AnalysisError : public Error {
 public:
  explicit AnalysisError(const std::string& what) : Error(what, ExitCode::AnalysisFailed) {}
};

/// An output could not be written (exit 3).
class OutputError : public Error {
 public:
  explicit OutputError(const std::string& what) : Error(what, ExitCode::OutputFailed) {}
};

}  // namespace rwcalc
