// Running gnuplot: the terminal preamble of a script, the subprocess, and the output file.
#include <fcntl.h>
#include <fmt/format.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <vector>

#include "core/cleanup.hpp"
#include "report/process.hpp"
#include "rwcalc/error.hpp"
#include "rwcalc/i18n.hpp"
#include "rwcalc/plot.hpp"
#include "rwcalc/printable.hpp"

extern char** environ;

namespace rwcalc {

namespace fs = std::filesystem;

namespace detail {
ProcessResult run_process(const std::string& command, const std::vector<std::string>& args, const fs::path& log,
                          const fs::path& cwd) {
  ProcessResult r;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0600);
  posix_spawn_file_actions_adddup2(&actions, STDOUT_FILENO, STDERR_FILENO);
  if (!cwd.empty()) posix_spawn_file_actions_addchdir_np(&actions, cwd.c_str());
  // A relative command path names a file from our directory, not from `cwd`.
  std::error_code ec;
  const auto absolute = fs::absolute(command, ec);
  std::vector<std::string> storage{!cwd.empty() && command.find('/') != std::string::npos && !ec ? absolute.string()
                                                                                                 : command};
  storage.insert(storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& s : storage) argv.push_back(s.data());
  argv.push_back(nullptr);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, storage.front().c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) {
    r.spawn_errno = rc;
    return r;
  }
  r.started = true;
  int wstatus = 0;
  pid_t waited = 0;
  while ((waited = waitpid(pid, &wstatus, 0)) < 0 && errno == EINTR) {
  }
  if (waited < 0) return r;  // status -1
  r.status = WIFEXITED(wstatus) ? WEXITSTATUS(wstatus) : 128 + WTERMSIG(wstatus);
  std::ifstream in(log, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  r.err = ss.str();
  return r;
}

}  // namespace detail

namespace {

using detail::ProcessResult;
using detail::run_process;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// A private temporary directory, removed with everything in it, also when a signal ends rwcalc
/// while gnuplot runs: the signal handler cannot list a directory, so each file is registered.
class ScratchDir {
 public:
  ScratchDir() {
    std::string templ = (fs::temp_directory_path() / "rwcalc-plot-XXXXXX").string();
    if (mkdtemp(templ.data()) == nullptr)
      throw OutputError(trf("cannot create a temporary directory for gnuplot: {}", std::strerror(errno)));
    path_ = templ;
    on_signal_.emplace_back(path_.string(), detail::RemoveOnSignal::Kind::Directory);
    for (const char* name : {"log", "gnuplot.log", "figure.gp", "figure.svg", "figure.png", "figure.pdf"})
      on_signal_.emplace_back((path_ / name).string(), detail::RemoveOnSignal::Kind::File);
  }
  ~ScratchDir() {
    std::error_code ec;
    fs::remove_all(path_, ec);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
  [[nodiscard]] const fs::path& path() const { return path_; }

 private:
  fs::path path_;
  std::deque<detail::RemoveOnSignal> on_signal_;  ///< unregistered after the removal above
};

/// Throws when gnuplot could not be started (a shell wrapper reports a missing binary as 127).
void require_started(const ProcessResult& r, const std::string& command) {
  if (r.started && r.status != 127) return;
  throw OutputError(
      trf("cannot run gnuplot ('{}': {}): plots need gnuplot; install it (Debian: apt-get install "
          "gnuplot-nox) or name the binary in the environment variable RWCALC_GNUPLOT",
          command, std::strerror(r.started ? ENOENT : r.spawn_errno)));
}

/// The last `lines` lines of gnuplot's message (they carry the error) joined by " | ", without the
/// caret line that points into the echoed command (it cannot stay aligned).
std::string tail_lines(const std::string& text, int lines) {
  std::vector<std::string> kept;
  std::size_t end = text.size();
  while (end > 0 && static_cast<int>(kept.size()) < lines) {
    const auto nl = text.rfind('\n', end - 1);
    const std::size_t begin = nl == std::string::npos ? 0 : nl + 1;
    auto line = text.substr(begin, end - begin);
    end = nl == std::string::npos ? 0 : nl;
    const auto first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line.find_first_not_of(" \t\r^") == std::string::npos) continue;
    line = line.substr(first, line.find_last_not_of(" \t\r") + 1 - first);
    kept.insert(kept.begin(), std::move(line));
  }
  std::string joined;
  for (const auto& l : kept) joined += (joined.empty() ? "" : " | ") + l;
  return joined;
}

}  // namespace

std::string gnuplot_string(std::string_view text) {
  std::string r = "'";
  for (char c : printable(text)) {
    if (c == '\'') r += '\'';
    r += c;
  }
  return r + "'";
}

PlotFormat plot_format_for(std::string_view path) {
  auto ext = fs::path(std::string(path)).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return std::tolower(c); });
  if (ext == ".svg") return PlotFormat::Svg;
  if (ext == ".png") return PlotFormat::Png;
  if (ext == ".pdf") return PlotFormat::Pdf;
  throw UsageError(trf("{}: unknown figure format '{}'; name the file .svg, .png or .pdf", path,
                       ext.empty() ? std::string(tr("(no extension)")) : ext));
}

std::string gnuplot_command() {
  const char* env = std::getenv("RWCALC_GNUPLOT");
  return env != nullptr && *env != '\0' ? env : "gnuplot";
}

bool gnuplot_available() {
  try {
    require_gnuplot();
    return true;
  } catch (const OutputError&) {
    return false;
  }
}

void require_gnuplot() {
  ScratchDir dir;
  const auto command = gnuplot_command();
  const auto r = run_process(command, {"--version"}, dir.path() / "log");
  require_started(r, command);
  if (r.status != 0)
    throw OutputError(trf("gnuplot ('{}') does not run: '{} --version' failed with status {}: {}", command, command,
                          r.status, tail_lines(r.err, 4)));
}

std::string full_script(const std::vector<Figure>& figures, PlotFormat format, int width_px,
                        const std::string& output_path) {
  int height = 0;
  for (const auto& f : figures) height += f.height_px;
  width_px = std::clamp(width_px, 200, 8000);
  height = std::clamp(height, 150, 16000);
  std::string s;
  s += fmt::format("# Generated by rwcalc {}. Run: gnuplot THIS_FILE\n", RWCALC_VERSION);
  s += "# Data are inline ($name << EOD blocks); coefficients are named variables: edit and re-run.\n";
  s += "set encoding utf8\n";
  switch (format) {
    case PlotFormat::Svg:
      s += fmt::format(
          "set terminal svg size {},{} fixed enhanced font 'Helvetica,13' linewidth 1.2 "
          "background '#ffffff'\n",
          width_px, height);
      break;
    case PlotFormat::Png:
      // pngcairo draws anti-aliased lines; the plain gd png terminal is the fallback.
      s += fmt::format(
          "if (strstrt(GPVAL_TERMINALS, 'pngcairo') > 0) {{\n"
          "  set terminal pngcairo size {0},{1} enhanced font 'Helvetica,11' linewidth 1.2 "
          "background '#ffffff'\n"
          "}} else {{\n"
          "  set terminal png size {0},{1} enhanced font 'Helvetica,11' background '#ffffff'\n"
          "}}\n",
          width_px, height);
      break;
    case PlotFormat::Pdf:
      s += fmt::format(
          "set terminal pdfcairo size {:.2f}in,{:.2f}in enhanced font 'Helvetica,9' "
          "linewidth 1.2 background '#ffffff'\n",
          width_px / 96.0, height / 96.0);
      break;
  }
  s += fmt::format("set output {}\n", gnuplot_string(output_path));
  const bool multi = figures.size() > 1;
  if (multi) s += "set multiplot\n";  // panels top to bottom, each as tall as its figure asks
  double top = 1.0;
  for (std::size_t i = 0; i < figures.size(); ++i) {
    const auto& f = figures[i];
    s += fmt::format("\n# ---- panel {}: {} ----\n", i + 1, f.name);
    if (multi) {
      const double frac = static_cast<double>(f.height_px) / height;
      s += "reset\n";
      s += fmt::format("set origin 0,{:.4f}\nset size 1,{:.4f}\n", top - frac, frac);
      top -= frac;
    }
    s += f.script;
  }
  if (multi) s += "unset multiplot\n";
  s += "set output\n";
  return s;
}

std::string render_figures(const std::vector<Figure>& figures, PlotFormat format, int width_px) {
  ScratchDir dir;
  // gnuplot runs inside the scratch directory and names its files relative to it, so no path
  // (the temporary directory's comes from TMPDIR) is ever written into the script.
  const std::string out_name = std::string("figure") + (format == PlotFormat::Svg   ? ".svg"
                                                        : format == PlotFormat::Png ? ".png"
                                                                                    : ".pdf");
  const fs::path out = dir.path() / out_name;
  const fs::path script = dir.path() / "figure.gp";
  {
    std::ofstream f(script, std::ios::binary);
    f << full_script(figures, format, width_px, out_name);
    if (!f) throw OutputError(trf("{}: cannot write the gnuplot script", script.string()));
  }
  const auto command = gnuplot_command();
  const auto r = run_process(command, {"figure.gp"}, dir.path() / "gnuplot.log", dir.path());
  require_started(r, command);
  if (r.status != 0)
    throw OutputError(trf("gnuplot ('{}') failed with status {}: {}", command, r.status, tail_lines(r.err, 4)));
  std::error_code ec;
  if (!fs::exists(out, ec) || fs::file_size(out, ec) == 0)
    throw OutputError(trf("gnuplot ('{}') produced no figure: {}", command, tail_lines(r.err, 4)));
  return slurp(out);
}

}  // namespace rwcalc
