#pragma once
// The one parser of a recording's lines: each line is blank, a comment (maybe metadata), the
// header row, or a data line, whose selected columns it reads into a Sample.
#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "layout.hpp"
#include "rwcalc/reader.hpp"

namespace rwcalc::detail {

enum class LineKind { Blank, Comment, Header, Data };

/// The selected columns of a data line.
struct Sample {
  std::int64_t integer = 0;  ///< pulses, or a counter reading's bit pattern
  double real = 0.0;         ///< angle / rate sample
  double time = 0.0;         ///< in the time column's own unit
  double time2 = 0.0;        ///< the second time column's
  double temperature = 0.0;
  double nanosec = 0.0;  ///< a split ROS 2 stamp's nanoseconds (the time column holds its seconds)
};

class LineParser {
 public:
  LineParser(std::string file, const ReadOptions& options);

  /// Read line number `line` (without its LF). Throws InputError naming the file and the line.
  LineKind parse(std::string_view text, std::size_t line, Sample& s);

  [[nodiscard]] const Layout& layout() const noexcept { return layout_; }
  [[nodiscard]] Metadata& metadata() noexcept { return meta_; }
  [[nodiscard]] const Metadata& metadata() const noexcept { return meta_; }
  [[nodiscard]] std::size_t first_data_line() const noexcept { return first_data_line_; }
  [[nodiscard]] std::size_t content_lines() const noexcept { return content_lines_; }
  [[nodiscard]] const std::string& file() const noexcept { return file_; }
  /// The input mode and units (known once the first data line fixed the columns).
  [[nodiscard]] const InputChoice& input() const noexcept { return input_; }
  [[nodiscard]] bool layout_known() const noexcept { return layout_known_; }

  /// Read the same lines as `lead`, each after it, taking the lead's split of a common data line
  /// rather than splitting it again (several columns of one file in one pass).
  void follow(const LineParser& lead) noexcept { lead_ = &lead; }
  /// Stop at the first data line: parse() then says Data without choosing the columns or reading
  /// the line (the header row alone is wanted).
  void stop_at_first_data() noexcept { stop_at_data_ = true; }

  /// The common data lines read on from `p` in one loop: while the layout is one integer column,
  /// each line that is an optional minus and 1–18 digits ended by LF (or CR LF) is appended to `out`
  /// and counted in `line` and content_lines(), `max_lines` at most. Returns where the first other line starts (or the
  /// last one without its line end before `end`): parse() takes that one, and reports it if need be.
  const char* plain_integer_lines(const char* p, const char* end, std::size_t& line, std::vector<std::int64_t>& out,
                                  std::size_t max_lines);
  /// The common data lines read on from `p` for several columns at once: while the columns are
  /// known and the values are not integers, each line of exactly the layout's fields (delimited
  /// or blank-separated, ended by LF or CR LF) whose fields with a slot (`slot_of_col`, −1: not
  /// wanted) read whole and finite with std::from_chars, as the general way would read them, puts
  /// those values onto `rows` in slot order (`slots` a line), `max_lines` lines at most, counted in
  /// `line` (each reader counts them with count_lines). Returns where the first other line starts:
  /// parse() takes that one.
  const char* plain_decimal_lines(const char* p, const char* end, std::size_t& line,
                                  const std::vector<int>& slot_of_col, std::size_t slots, std::vector<double>& rows,
                                  std::size_t max_lines);
  /// Lines another parser read in bulk for this one (it follows that one).
  void count_lines(std::size_t n) noexcept { content_lines_ += n; }
  /// The sample a line gives whose fields with a slot read as `row` (plain_decimal_lines).
  [[nodiscard]] Sample row_sample(const double* row, const std::vector<int>& slot_of_col) const noexcept;

 private:
  [[noreturn]] void fail(const std::string& message) const;
  void split(std::string_view line);
  void check_foreign_delimiters(std::string_view line) const;
  bool header_row(std::string_view line);
  bool read_fields(const std::vector<std::string_view>& fields, Sample& s, bool report);
  bool read_field(std::string_view f, Role role, Sample& s, bool report);
  [[nodiscard]] bool plain_layout() const noexcept;
  bool plain_integer(std::string_view t, Sample& s) const;
  const char* plain_run(const char* p, const char* end, std::vector<std::int64_t>& out, std::size_t max_lines) const;
  bool delimited_data_line(std::string_view text, Sample& s);
  bool read_integer(std::string_view f, std::string_view t, Sample& s, bool report);
  void assign(Sample& s, Role role, double v) const noexcept;
  void join_stamp(Sample& s) const noexcept;
  const char* decimal_run(const char* p, const char* end, const std::vector<int>& slot_of_col, std::vector<double>& out,
                          std::size_t max_lines) const;
  [[nodiscard]] bool integer_mode() const noexcept {
    return input_.mode == InputMode::Pulses || input_.mode == InputMode::Counter;
  }

  std::string file_;
  const ReadOptions& opt_;
  std::size_t line_ = 0;
  std::size_t content_lines_ = 0;  // lines that are not blank
  std::size_t first_data_line_ = 0;
  bool layout_known_ = false;
  Layout layout_;
  InputChoice input_;
  Metadata meta_;
  std::int64_t counter_lo_ = 0, counter_max_ = 0;  // the readings a counter can give
  std::vector<std::string_view> fields_;
  const LineParser* lead_ = nullptr;
  std::size_t split_line_ = 0;  // the line fields_ holds, when the common path split it
  std::string scratch_;
  /// plain_integer_lines reads stretches of this many bytes or more in two halves, in parallel.
  static constexpr std::ptrdiff_t kSplitBytes = std::ptrdiff_t{1} << 16;
  std::vector<std::int64_t> second_half_;  // the second half's lines, until the first half reaches them
  std::vector<double> second_rows_;        // the same for plain_decimal_lines
  bool stop_at_data_ = false;
};

}  // namespace rwcalc::detail
