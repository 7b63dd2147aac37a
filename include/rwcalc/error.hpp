#pragma once
/// @file error.hpp
/// Error types of rwcalc and the process exit status each one maps to.
///
/// The library throws; the command-line layer catches at one place (cli::run) and turns the
/// exception into a message on stderr and an exit status. Exit statuses:
///   0  success
///   1  the analysis cannot be done on valid input (too short a record, too few τ for a fit, …)
///   2  bad input or bad usage (unreadable file, malformed line, invalid option value)
///   3  an output could not be written (exists without --force, directory missing, disk full)
#include <cstddef>
#include <stdexcept>
#include <string>

namespace rwcalc {

enum class ExitCode : int { Ok = 0, AnalysisFailed = 1, BadInput = 2, OutputFailed = 3 };

/// Base of all rwcalc errors.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what, ExitCode code) : std::runtime_error(what), code_(code) {}
  [[nodiscard]] ExitCode code() const noexcept { return code_; }

 private:
  ExitCode code_;
};

/// Bad input data: names the file, the line (1-based, 0 when no line applies) and what was wrong.
/// what() reads "FILE:LINE: MESSAGE" (or "FILE: MESSAGE").
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

/// An output file could not be written (exit 3).
class OutputError : public Error {
 public:
  explicit OutputError(const std::string& what) : Error(what, ExitCode::OutputFailed) {}
};

}  // namespace rwcalc
