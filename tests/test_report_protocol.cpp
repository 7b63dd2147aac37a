// The test protocol of 'rwcalc report --lab-profile': its first page (approval block, number,
// instruments with verification dates, signature lines) in the HTML, the PDF and the DOCX, in
// Russian and English; numbers as metrology writes them (GUM rounding, no e-notation); a Russian
// report with no English left in it; plural forms; the profile's errors; a missing tool is exit 3.
// The PDF checks skip with a message without chromium and pdftotext, the DOCX checks without pandoc.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <regex>
#include <set>
#include <tuple>

#include "rwcalc/i18n.hpp"
#include "rwcalc/lab_profile.hpp"
#include "rwcalc/quantity_text.hpp"
#include "rwcalc/version.hpp"
#include "test_support.hpp"

namespace fs = std::filesystem;
using rwcalc::Language;
using rwcalc::LanguageScope;
using rwcalc::test::concat;
using rwcalc::test::run_cli;
using rwcalc::test::ScopedEnv;
using rwcalc::test::slurp;
using rwcalc::test::source_path;
using rwcalc::test::TempDir;

namespace {

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }
bool installed(const char* program) {
  return std::system(("command -v " + std::string(program) + " >/dev/null 2>&1").c_str()) == 0;
}

/// The standard output of a command run through the shell (arguments quoted by the caller).
std::string command_output(const std::string& command) {
  std::string out;
  if (FILE* p = ::popen(command.c_str(), "r")) {
    char buf[65536];
    for (std::size_t n; (n = std::fread(buf, 1, sizeof buf, p)) > 0;) out.append(buf, n);
    ::pclose(p);
  }
  return out;
}

/// `text` with every piece from `open` to the next `close` (both included) replaced by a blank.
/// (std::regex recurses once per character matched: a megabyte page overflows the stack.)
std::string without(const std::string& text, const std::string& open, const std::string& close) {
  std::string out;
  std::size_t at = 0;
  for (std::size_t p; (p = text.find(open, at)) != std::string::npos;) {
    out += text.substr(at, p - at) + " ";
    const std::size_t e = text.find(close, p + open.size());
    at = e == std::string::npos ? text.size() : e + close.size();
  }
  return out + text.substr(std::min(at, text.size()));
}

/// The text a reader sees in an HTML page: no style, no tags, no inline data, the entities the
/// report writes resolved.
std::string html_text(std::string html) {
  html = without(without(html, "<style>", "</style>"), "<", ">");
  for (const auto& [entity, c] : std::vector<std::pair<std::string, std::string>>{{"&lt;", "<"},
                                                                                  {"&gt;", ">"},
                                                                                  {"&quot;", "\""},
                                                                                  {"&#39;", "'"},
                                                                                  {"&#46;", "."},
                                                                                  {"&nbsp;", " "},
                                                                                  {"&amp;", "&"}})
    for (std::size_t p; (p = html.find(entity)) != std::string::npos;) html.replace(p, entity.size(), c);
  return html;
}

/// The paragraphs' text of a DOCX (word/document.xml, its <w:t> runs), read with Python's zipfile.
std::string docx_text(const fs::path& docx) {
  const std::string xml = command_output(
      "/usr/bin/python3 -c \"import sys, zipfile; sys.stdout.write(zipfile.ZipFile("
      "sys.argv[1]).read('word/document.xml').decode())\" '" +
      docx.string() + "'");
  std::string text;
  for (std::size_t p = 0; (p = xml.find("<w:t", p)) != std::string::npos; ++p) {
    if (xml[p + 4] != '>' && xml[p + 4] != ' ') continue;  // <w:tbl>, <w:tc>…
    const std::size_t from = xml.find('>', p) + 1;
    text += xml.substr(from, xml.find('<', from) - from) + " ";
  }
  return html_text(text);  // the XML's entities are those of HTML
}

/// Every "value ± uncertainty" of a text whose two numbers do not end at the same decimal place,
/// and (in `pairs`) how many there are. "(8.45 ± 0.21)·10⁻⁸" counts as its mantissas.
std::vector<std::string> pairs_rounded_apart(const std::string& text, std::size_t& pairs) {
  static const std::regex pair("(\\d+(?:[.,](\\d+))?) ± (\\d+(?:[.,](\\d+))?)");
  std::vector<std::string> bad;
  pairs = 0;
  for (std::sregex_iterator i(text.begin(), text.end(), pair), end; i != end; ++i, ++pairs)
    if ((*i)[2].length() != (*i)[4].length()) bad.push_back((*i)[0].str());
  return bad;
}

/// A number in e-notation: "2.1e-05", "1e+06".
bool has_e_notation(const std::string& text) { return std::regex_search(text, std::regex("\\de[-+]\\d")); }

struct Protocol {
  int status = -1;
  std::string err, html, pdf, docx;  ///< the text of each ("" when not made)
  bool pdf_made = false, docx_made = false;
};

/// The five GL-2D runs as a test protocol with the profile of every key, as HTML, PDF and DOCX.
Protocol make_protocol(const char* lang, const fs::path& dir) {
  Protocol p;
  const auto r = run_cli(
      concat(concat({"report"}, rwcalc::test::gl2d_runs()),
             {"--lang", lang, "--gyro", "GL-2D", "--lab-profile", source_path("tests/data/lab-profile.yaml").string(),
              "--protocol-number", "17/2026", "-o", dir.string(), "--pdf", "--docx", "--quiet"}));
  p.status = r.status;
  p.err = r.err;
  p.html = html_text(slurp(dir / "report.html"));
  p.pdf_made = fs::exists(dir / "report.pdf");
  if (p.pdf_made && installed("pdftotext"))
    p.pdf = command_output("pdftotext -enc UTF-8 '" + (dir / "report.pdf").string() + "' -");
  p.docx_made = fs::exists(dir / "report.docx");
  if (p.docx_made) p.docx = docx_text(dir / "report.docx");
  return p;
}

class ProtocolReport : public ::testing::TestWithParam<const char*> {
 protected:
  static TempDir& dir() {
    static TempDir d;
    return d;
  }
  /// The protocol in `lang`, made on first use: each test runs in a process of its own, and a
  /// protocol takes about 12 s of CPU to make, so a test makes only the language it reads.
  static const Protocol& protocol(const std::string& lang) {
    static std::map<std::string, Protocol> made;
    if (!made.contains(lang)) made[lang] = make_protocol(lang.c_str(), dir().path() / lang);
    return made[lang];
  }
};

/// What the protocol's first page must carry in each language.
std::vector<std::string> protocol_marks(const std::string& lang) {
  const bool ru = lang == "ru";
  return {ru ? "УТВЕРЖДАЮ" : "APPROVED",
          ru ? "№ 17/2026" : "No. 17/2026",
          "Начальник лаборатории",
          "И. И. Иванов",
          "Частотомер электронно-счётный",  // its type "Ч3-85/6" may break at the hyphen
          "Камера климатическая КТК-800",
          "1123",
          ru ? "15.03.2026" : "2026-03-15",
          ru ? "12.01.2026" : "2026-01-12",
          ru ? "20.05.2026" : "2026-05-20",
          ru ? "Испытания провёл" : "Tests performed by",
          "П. П. Петров",
          ru ? "Проверил" : "Checked by",
          "С. С. Сидорова",
          ru ? "Средства измерений" : "Measuring instruments",
          ru ? "Условия испытаний" : "Ambient conditions",
          ru ? "стандартная неопределённость" : "standard uncertainty"};
}

/// Blanks and line breaks as one blank (a PDF's narrow table cell wraps its text).
std::string one_line(const std::string& text) {
  std::string out;
  for (char c : text) {
    const bool blank = c == ' ' || c == '\n' || c == '\t' || c == '\f' || c == '\r';
    if (!blank)
      out += c;
    else if (!out.empty() && out.back() != ' ')
      out += ' ';
  }
  return out;
}

void expect_protocol_text(const std::string& raw, const std::string& lang, const char* what) {
  ASSERT_GT(raw.size(), 1000U) << what;
  const std::string text = one_line(raw);
  for (const auto& mark : protocol_marks(lang)) EXPECT_TRUE(has(text, mark)) << what << ": no '" << mark << "'";
  EXPECT_FALSE(has_e_notation(text)) << what << ": a number in e-notation";
  std::size_t pairs = 0;
  const auto bad = pairs_rounded_apart(text, pairs);
  // Five runs × (N, B) in the protocol's results and in Table 1 twice over, the fit tables, two conditions.
  EXPECT_GE(pairs, 30U) << what;
  EXPECT_TRUE(bad.empty()) << what << ": rounded to different digits: " << (bad.empty() ? "" : bad.front());
}

}  // namespace

TEST_P(ProtocolReport, HtmlPdfAndDocxCarryTheProtocolWithNumbersAsMetrologyWritesThem) {
  if (!installed("gnuplot")) GTEST_SKIP() << "gnuplot not found: the report's figures need it";
  const std::string lang = GetParam();
  const Protocol& p = protocol(lang);
  // A tool that is not installed is an error for its output (3), the HTML written all the same.
  const bool tools = installed("chromium") && installed("pandoc");
  EXPECT_EQ(p.status, tools ? 0 : 3) << p.err;
  expect_protocol_text(p.html, lang, "HTML");
  if (lang == "ru") {
    EXPECT_TRUE(has(p.html, "расширенной неопределённости, P = 0,95")) << "the GOST 34100.3 term";
    EXPECT_TRUE(has(p.html, "21,40 ± 0,26")) << "a condition with its uncertainty, decimal comma";
    EXPECT_TRUE(has(p.html, "0,000851 ± 0,000021")) << "N at −50 °C by the GUM rule";
  } else {
    EXPECT_TRUE(has(p.html, "coverage interval, p = 0.95"));
    EXPECT_TRUE(has(p.html, "0.000851 ± 0.000021"));
  }
  if (!p.docx_made)
    ADD_FAILURE() << "no DOCX" << (installed("pandoc") ? "" : " (pandoc is not installed: apt-get install pandoc)");
  else
    expect_protocol_text(p.docx, lang, "DOCX");
  if (!installed("chromium") || !installed("pdftotext"))
    GTEST_SKIP() << "PDF not checked: chromium or pdftotext (poppler-utils) not installed";
  ASSERT_TRUE(p.pdf_made);
  expect_protocol_text(p.pdf, lang, "PDF");
  // The approval block and the signature lines are on the first page, with the protocol number
  // in its foot.
  const auto first_page = p.pdf.substr(0, p.pdf.find('\f'));
  for (const char* mark : {"УТВЕРЖДАЮ", "APPROVED", "Проверил", "Checked by"})
    if (has(p.pdf, mark)) {
      EXPECT_TRUE(has(first_page, mark)) << mark << " not on the first page";
    }
}

INSTANTIATE_TEST_SUITE_P(Languages, ProtocolReport, ::testing::Values("ru", "en"));

TEST_P(ProtocolReport, ARussianReportShowsNoEnglishButNamesAndIdentifiers) {
  if (std::string(GetParam()) != "ru") GTEST_SKIP() << "Russian only";
  if (!installed("gnuplot")) GTEST_SKIP() << "gnuplot not found: the report's figures need it";
  protocol("ru");
  std::string html = slurp(dir().path() / "ru" / "report.html");
  // The figures' text (inline SVG as base64) is part of what a reader sees.
  std::string figures = command_output(
      "/usr/bin/python3 -c \"import re, sys, base64; h = open(sys.argv[1]).read(); "
      "print(' '.join(base64.b64decode(m).decode() for m in re.findall('base64,([A-Za-z0-9+/=]+)', h)))\" '" +
      (dir().path() / "ru" / "report.html").string() + "'");
  ASSERT_TRUE(has(figures, "<svg")) << "no figure decoded";
  // <code> holds the SHA-256 sums and suggested command lines: identifiers.
  std::string text = html_text(without(html, "<code>", "</code>"));
  // A figure's words are its <text> elements (its <title> and <desc> are gnuplot's, never shown).
  for (std::size_t p = 0; (p = figures.find("<text", p)) != std::string::npos;) {
    const std::size_t from = figures.find('>', p) + 1, to = figures.find("</text>", from);
    text += " " + html_text(figures.substr(from, to - from));
    p = to;
  }
  // What may stay as typed: the program's version line, file names and paths, and these identifiers.
  for (std::size_t p; (p = text.find(rwcalc::version_line())) != std::string::npos;)
    text.erase(p, rwcalc::version_line().size());
  text = std::regex_replace(text, std::regex("[^\\s()]*[./][^\\s()]*"), " ");  // file names, paths, 17/2026
  const std::set<std::string> identifiers = {"IEEE", "GL-2D", "SHA-256", "QNBKR", "UTC", "rwcalc"};
  std::set<std::string> english;
  const std::regex word("[A-Za-z][A-Za-z0-9-]*[A-Za-z0-9]");
  for (std::sregex_iterator i(text.begin(), text.end(), word), end; i != end; ++i) {
    const std::string w = i->str();
    // Single letters and symbols of quantities (N, B, Q, K, R, P, u, τ) and two-letter units stay.
    if (w.size() >= 3 && !identifiers.count(w)) english.insert(w);
  }
  std::string list;
  for (const auto& w : english) list += w + " ";
  EXPECT_TRUE(english.empty()) << "English words in the Russian report: " << list;
}

// ---- numbers as metrology writes them ----------------------------------------------------------

TEST(QuantityText, UncertaintyToOneOrTwoDigitsAndTheValueToTheSameDigit) {
  const LanguageScope en(Language::English);
  EXPECT_EQ(rwcalc::value_with_uncertainty(0.000845, 2.1e-5), "0.000845 ± 0.000021");
  EXPECT_EQ(rwcalc::value_with_uncertainty(0.007, 0.00087), "0.0070 ± 0.0009");  // 0.87: one digit
  EXPECT_EQ(rwcalc::value_with_uncertainty(0.00703, 0.00123), "0.0070 ± 0.0012");
  EXPECT_EQ(rwcalc::value_with_uncertainty(12345.0, 230.0), "12350 ± 230");
  EXPECT_EQ(rwcalc::value_with_uncertainty(1.2345e-8, 4.6e-10), "(1.23 ± 0.05) × 10⁻⁸");
  EXPECT_EQ(rwcalc::value_with_uncertainty(21.4, 0.26), "21.40 ± 0.26");
  EXPECT_EQ(rwcalc::value_with_uncertainty(3.0, 0.0), "3");  // no uncertainty: the value alone
  // 0.0996 rounds to 0.10 (two digits, the first a 1); 0.0096 to 0.010; 0.0087 to 0.009.
  EXPECT_EQ(rwcalc::gum_last_digit(0.0996), -2);
  EXPECT_EQ(rwcalc::gum_last_digit(0.0096), -3);
  EXPECT_EQ(rwcalc::gum_last_digit(0.0087), -3);
  EXPECT_EQ(rwcalc::gum_last_digit(0.029), -3);
  EXPECT_EQ(rwcalc::gum_last_digit(87.0), 1);
  EXPECT_EQ(rwcalc::interval_at(0.0008043, 0.0008831, -6), "[0.000804, 0.000883]");
}

TEST(QuantityText, NoNumberIsWrittenInENotation) {
  {
    const LanguageScope en(Language::English);
    EXPECT_EQ(rwcalc::number_text(2.1e-5, 2), "2.1 × 10⁻⁵");
    EXPECT_EQ(rwcalc::number_text(1.5e7, 3), "1.5 × 10⁷");
    EXPECT_EQ(rwcalc::number_text(0.000845, 3), "0.000845");
    EXPECT_EQ(rwcalc::number_text(99999.6, 3), "100000");
    EXPECT_EQ(rwcalc::number_text(-0.25, 3), "-0.25");
    EXPECT_EQ(rwcalc::number_at(1.2e-9, -10), "1.2 × 10⁻⁹");
  }
  const LanguageScope ru(Language::Russian);
  EXPECT_EQ(rwcalc::number_text(2.1e-5, 2), "2.1·10⁻⁵");  // the decimal comma comes with localize_html
  EXPECT_EQ(rwcalc::localize_html("<td>" + rwcalc::value_with_uncertainty(1.2345e-8, 4.6e-10) + "</td>"),
            "<td>(1,23 ± 0,05)·10⁻⁸</td>");
  for (double v : {1e-300, 3.3e-12, 7e-7, 0.5, 12.0, 4.4e9, 1e300})
    EXPECT_FALSE(has_e_notation(rwcalc::number_text(v, 4))) << v;
}

// ---- plural forms and dates ----------------------------------------------------------------------

TEST(PluralForms, RussianTakesTheFormOfTheCountEnglishTheSingularForOne) {
  const char* one = "report written to {} ({} run{})\n";
  const char* many = "report written to {} ({} runs{})\n";
  const std::vector<std::pair<unsigned long long, std::string>> cases = {{1, "(1 запуск)"},    {2, "(2 запуска)"},
                                                                         {5, "(5 запусков)"},  {11, "(11 запусков)"},
                                                                         {21, "(21 запуск)"},  {64, "(64 запуска)"},
                                                                         {72, "(72 запуска)"}, {111, "(111 запусков)"},
                                                                         {0, "(0 запусков)"}};
  {
    const LanguageScope ru(Language::Russian);
    for (const auto& [n, words] : cases) EXPECT_TRUE(has(rwcalc::trnf(one, many, n, "x", n, ""), words)) << n;
  }
  const LanguageScope en(Language::English);
  EXPECT_TRUE(has(rwcalc::trnf(one, many, 1, "x", 1, ""), "(1 run)"));
  EXPECT_TRUE(has(rwcalc::trnf(one, many, 21, "x", 21, ""), "(21 runs)"));
  EXPECT_EQ(rwcalc::russian_plural_form(64), 1);
  EXPECT_EQ(rwcalc::russian_plural_form(72), 1);
  EXPECT_EQ(rwcalc::russian_plural_form(65), 2);
  EXPECT_EQ(rwcalc::russian_plural_form(12), 2);
}

TEST(PluralForms, TheCatalogueReadsPluralEntries) {
  const auto e = rwcalc::i18n_detail::parse_po(
      "msgid \"{} block\"\nmsgid_plural \"{} blocks\"\nmsgstr[0] \"{} блок\"\nmsgstr[1] \"{} блока\"\n"
      "msgstr[2] \"{} блоков\"\n\nmsgid \"{} half\"\nmsgid_plural \"{} halves\"\nmsgstr[0] \"{} x\"\nmsgstr[1] \"\"\n"
      "msgstr[2] \"\"\n");
  ASSERT_EQ(e.size(), 1U);  // the second is not translated in every form
  EXPECT_EQ(e[0].plural_id, "{} blocks");
  EXPECT_EQ(e[0].forms, (std::vector<std::string>{"{} блок", "{} блока", "{} блоков"}));
}

TEST(PluralForms, TheTextReportCountsReplicatesAndBlocksInRussian) {
  const auto r = run_cli({"analyze", "--lang", "ru", rwcalc::test::gl2d_runs().front()});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_FALSE(has(r.out, "64 повторений")) << r.out;
  EXPECT_FALSE(has(r.out, "72 блоков")) << r.out;
  EXPECT_TRUE(std::regex_search(r.out, std::regex("\\d+ (повторени[ея]|повторений)"))) << r.out;
  // The B estimate in words, not the option's value.
  EXPECT_FALSE(has(r.out, "B: fit")) << r.out;
  EXPECT_TRUE(has(r.out, "оценка B по аппроксимации пятичленной моделью")) << r.out;
}

TEST(ProtocolDates, RussianWritesDayMonthYearEnglishIso) {
  const rwcalc::CalendarDate d{2026, 11, 27};
  {
    const LanguageScope ru(Language::Russian);
    EXPECT_EQ(rwcalc::date_text(d), "27.11.2026");
  }
  const LanguageScope en(Language::English);
  EXPECT_EQ(rwcalc::date_text(d), "2026-11-27");
}

TEST(ProtocolDates, TheTimeStampIsLocalTimeWithItsOffset) {
  if (!installed("gnuplot")) GTEST_SKIP() << "gnuplot not found";
  TempDir dir;
  const ScopedEnv tz("TZ", "MSK-3");  // POSIX: 3 h east of UTC, no time-zone data needed
  const auto r = run_cli({"report", "--lang", "ru", "--no-figures", "--quiet", "-o", dir.path().string(),
                          rwcalc::test::gl2d_runs().front()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto html = slurp(dir.path() / "report.html");
  EXPECT_TRUE(std::regex_search(html, std::regex("\\d\\d\\.\\d\\d\\.20\\d\\d \\d\\d:\\d\\d:\\d\\d UTC\\+03:00")))
      << "no local time with its offset";
  EXPECT_FALSE(std::regex_search(html, std::regex("20\\d\\d-\\d\\d-\\d\\d \\d\\d:\\d\\d")));
}

// ---- the lab profile's errors --------------------------------------------------------------------

TEST(LabProfile, ReadsEveryKey) {
  const auto p = rwcalc::read_lab_profile(source_path("tests/data/lab-profile.yaml").string());
  EXPECT_EQ(p.approver.name, "И. И. Иванов");
  EXPECT_EQ(p.checker.position, "Ведущий инженер");
  ASSERT_EQ(p.instruments.size(), 3U);
  EXPECT_EQ(p.instruments[1].verified.day, 12);
  EXPECT_EQ(p.instruments[1].valid_until->year, 2027);
  EXPECT_FALSE(p.instruments[2].valid_until.has_value());
  ASSERT_EQ(p.conditions.size(), 3U);
  EXPECT_DOUBLE_EQ(p.conditions[2].value, 100.62);  // written 100,62
  EXPECT_FALSE(p.conditions[2].uncertainty.has_value());
  EXPECT_FALSE(p.customer.empty());
  EXPECT_FALSE(p.method.empty());
  EXPECT_FALSE(p.address.empty());
  EXPECT_FALSE(p.accreditation.empty());
}

TEST(LabProfile, EachErrorNamesTheFileTheLineAndWhatIsWrong) {
  TempDir dir;
  const std::vector<std::tuple<std::string, std::string, std::string>> cases = {
      {"laboratory: L\nlaborator: typo\n", ":2:", "unknown key 'laborator'"},
      {"laboratory: [a, b]\n", ":1:", "'laboratory' must be a text"},
      {"instruments:\n  - type: T\n    serial: \"1\"\n    verified: 2026-02-30\n", ":4:", "is not a date"},
      {"instruments:\n  - type: T\n    verified: 2026-02-03\n", ":2:", "type, serial and verified"},
      {"conditions:\n  - quantity: t\n    value: warm\n    unit: C\n", ":3:", "'warm' is not a number"},
      {"approver:\n  position: P\n  nam: N\n", ":3:", "no key 'nam'"},
      {"laboratory: L\nlaboratory: M\n", ":2:", "given twice"},
      {"laboratory: \"unterminated\n", ":", "not valid YAML"},
      {"- a list\n", ":1:", "must be a mapping"},
  };
  int k = 0;
  for (const auto& [yaml, where, what] : cases) {
    const auto file = dir.write(fmt::format("p{}.yaml", k++), yaml);
    const auto r = run_cli({"report", "--no-figures", "--quiet", "--lab-profile", file.string(), "-o",
                            (dir.path() / "out").string(), rwcalc::test::gl2d_runs().front()});
    EXPECT_EQ(r.status, 2) << yaml;
    EXPECT_TRUE(has(r.err, file.string() + where)) << yaml << r.err;
    EXPECT_TRUE(has(r.err, what)) << yaml << r.err;
    EXPECT_FALSE(fs::exists(dir.path() / "out" / "report.html")) << "checked before the analysis";
  }
}

TEST(LabProfile, TextFromTheProfileIsEscapedForHtmlAndCss) {
  TempDir dir;
  const auto file = dir.write("p.yaml", "laboratory: \"<script>alert(1)</script> & 1.5\"\n");
  const auto r =
      run_cli({"report", "--no-figures", "--quiet", "--lang", "ru", "--lab-profile", file.string(), "--protocol-number",
               "x\"}</style><b>x", "-o", dir.path().string(), rwcalc::test::gl2d_runs().front()});
  ASSERT_EQ(r.status, 0) << r.err;
  const auto html = slurp(dir.path() / "report.html");
  EXPECT_FALSE(has(html, "<script>"));
  EXPECT_TRUE(has(html, "&lt;script&gt;alert(1)&lt;/script&gt; &amp; 1.5")) << "as typed: no decimal comma";
  EXPECT_FALSE(has(html, "</style><b>x")) << "the number left the CSS string";
  EXPECT_TRUE(has(html, "x&quot;}&lt;/style&gt;&lt;b&gt;x")) << "the number in the page";
}

TEST(LabProfile, ProtocolNumberNeedsTheProfileAndTheProfileExcludesLab) {
  const auto run = rwcalc::test::gl2d_runs().front();
  EXPECT_EQ(run_cli({"report", "--protocol-number", "1", "-o", "x", run}).status, 2);
  EXPECT_EQ(run_cli({"report", "--lab", "L", "--lab-profile", source_path("tests/data/lab-profile.yaml").string(), "-o",
                     "x", run})
                .status,
            2);
}

// ---- a missing tool is an error for the output asked for ---------------------------------------

TEST(ReportTools, WithoutPandocOrChromiumTheHtmlIsWrittenAndTheStatusIs3) {
  TempDir dir;
  const ScopedEnv path("PATH", dir.path().c_str());  // a directory with neither program
  const ScopedEnv chromium("RWCALC_CHROMIUM", nullptr);
  const ScopedEnv pandoc("RWCALC_PANDOC", nullptr);
  for (const char* option : {"--pdf", "--docx"}) {
    const auto out = dir.path() / option;
    const auto r =
        run_cli({"report", option, "--no-figures", "--quiet", "-o", out.string(), rwcalc::test::gl2d_runs().front()});
    EXPECT_EQ(r.status, 3) << option << r.err;
    EXPECT_TRUE(fs::exists(out / "report.html")) << option;
    EXPECT_TRUE(has(r.err, option)) << r.err;
    EXPECT_TRUE(has(r.err, "apt-get install")) << r.err;
  }
}

TEST(ReportTools, DocxIsWrittenByPandocAndNotReplacedWithoutForce) {
  if (!installed("pandoc")) GTEST_SKIP() << "pandoc not installed (apt-get install pandoc)";
  TempDir dir;
  const auto args = std::vector<std::string>{
      "report", "--docx", "--no-figures", "--quiet", "-o", dir.path().string(), rwcalc::test::gl2d_runs().front()};
  const auto r = run_cli(args);
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_TRUE(has(docx_text(dir.path() / "report.docx"), "Table 1"));
  EXPECT_TRUE(has(r.out, "DOCX written to"));
  EXPECT_EQ(run_cli(args).status, 3);
  EXPECT_EQ(run_cli(concat(args, {"--force"})).status, 0);
}

// ---- analyse, the manual page and the completion -----------------------------------------------

TEST(CommandLine, AnalyseIsAnalyze) {
  const auto a = run_cli({"analyse", "--json", rwcalc::test::gl2d_runs().front()});
  const auto b = run_cli({"analyze", "--json", rwcalc::test::gl2d_runs().front()});
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_EQ(a.out, b.out);
}

TEST(CommandLine, TheManualListsEveryEnvironmentVariableAndHasExamples) {
  const auto man = run_cli({"man"});
  ASSERT_EQ(man.status, 0);
  EXPECT_TRUE(has(man.out, ".SH EXAMPLES"));
  EXPECT_TRUE(has(man.out, "Also spelt \\fBanalyse"));
  // Every variable the sources read.
  std::set<std::string> vars;
  const std::regex getenv_call("(?:getenv|find_program)\\(\"([A-Z_]+)\"");
  for (const auto& f : fs::recursive_directory_iterator(source_path("src"))) {
    const auto text = slurp(f.path());
    for (std::sregex_iterator i(text.begin(), text.end(), getenv_call), end; i != end; ++i) vars.insert((*i)[1]);
  }
  vars.erase("PATH");
  EXPECT_GE(vars.size(), 5U);
  for (const auto& v : vars) EXPECT_TRUE(has(man.out, ".B " + v + "\n")) << v;
  for (const char* v : {"RWCALC_LANG", "RWCALC_CHROMIUM", "RWCALC_PANDOC", "TMPDIR"})
    EXPECT_TRUE(has(man.out, ".B " + std::string(v) + "\n")) << v;
}

TEST(CommandLine, TheCompletionOffersOptionValues) {
  const auto c = run_cli({"completion"});
  ASSERT_EQ(c.status, 0);
  for (const char* line : {"--estimator) values=\"oadev adev mdev ohdev hdev\"", "--lang) values=\"en ru\"",
                           "--output-unit) values=\"deg/h deg/s rad/s m/s^2 g mg ug\"",
                           "--b-estimate) values=\"fit sigma-min avg100\"", "    analyse|analyze) opts="})
    EXPECT_TRUE(has(c.out, line)) << line;
  if (!installed("bash")) GTEST_SKIP() << "no bash";
  TempDir dir;
  const auto script = dir.write("c.bash", c.out);
  const auto out = command_output("bash -c 'source \"" + script.string() +
                                  "\"; COMP_WORDS=(rwcalc allan --estimator m); COMP_CWORD=3; _rwcalc; "
                                  "printf \"%s\\n\" \"${COMPREPLY[@]}\"'");
  EXPECT_EQ(out, "mdev\n");
}
