// The Russian output: the message catalogue (po/ru.po compiled in), the decimal comma, and the
// commands under --lang ru and RWCALC_LANG. That every message of the code has a Russian entry is
// checked by scripts/update-po.sh --check (the test i18n_catalogue_complete).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cstdlib>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <random>
#include <regex>
#include <string>
#include <vector>

#include "rwcalc/i18n.hpp"
#include "rwcalc/sensor.hpp"
#include "test_support.hpp"

using rwcalc::Language;
using rwcalc::LanguageScope;
using rwcalc::localize_html;
using rwcalc::localize_numbers;
using rwcalc::test::run_cli;
using rwcalc::test::slurp;
using rwcalc::test::TempDir;

namespace {

/// The replacement fields of a format string ("{}", "{:.2f}", "{0}"), in order.
std::vector<std::string> fields(const std::string& text) {
  std::vector<std::string> out;
  static const std::regex field(R"(\{[^{}]*\})");
  for (auto it = std::sregex_iterator(text.begin(), text.end(), field); it != std::sregex_iterator(); ++it)
    out.push_back(it->str());
  return out;
}

/// "" when the translation formats the English message's arguments correctly: with automatic
/// numbering the same fields in the same order; with explicit indices ("{1} … {0}", to reorder
/// or leave out a word such as a plural suffix) each index names an argument with the same spec.
std::string field_problem(const std::string& english, const std::string& russian) {
  const auto e = fields(english), r = fields(russian);
  const bool explicit_r = std::any_of(r.begin(), r.end(), [](const std::string& f) { return std::isdigit(f[1]); });
  if (!explicit_r) return e == r ? "" : "fields differ or are reordered without indices";
  auto spec = [](const std::string& f) { return f.substr(f.find_first_not_of("0123456789", 1)); };
  for (const auto& f : r) {
    if (!std::isdigit(f[1])) return "automatic and explicit indices mixed";
    const auto k = std::stoul(f.substr(1));
    if (k >= e.size()) return "index beyond the arguments: " + f;
    if (spec(f) != spec(e[k])) return "spec differs from the English field: " + f;
  }
  return "";
}

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

bool in_catalogue(const std::string& english) {
  const auto& entries = rwcalc::i18n_detail::russian_entries();
  return std::any_of(entries.begin(), entries.end(), [&](const auto& e) { return e.id == english; });
}

/// A static 6-axis IMU of white noise, 200 s at 100 Hz: gyro in °/s, accelerometer in g.
std::string imu_csv() {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> z;
  std::string s = "gyro_x_dps,gyro_y_dps,gyro_z_dps,acc_x_g,acc_y_g,acc_z_g\n";
  for (int k = 0; k < 20000; ++k)
    s += fmt::format("{:.6f},{:.6f},{:.6f},{:.7f},{:.7f},{:.7f}\n", 0.1 + 0.05 * z(rng), 0.1 + 0.05 * z(rng),
                     0.1 + 0.05 * z(rng), 0.002 * z(rng), 0.002 * z(rng), -1 + 0.002 * z(rng));
  return s;
}

std::vector<std::string> imu_args(const std::filesystem::path& file, std::vector<std::string> more) {
  return rwcalc::test::concat({"imu", file.string(), "--rate", "100", "--gyro", "gyro_x_dps,gyro_y_dps,gyro_z_dps",
                               "--accel", "acc_x_g,acc_y_g,acc_z_g"},
                              more);
}

}  // namespace

TEST(Catalogue, EveryEntryKeepsTheReplacementFieldsAndLineBreaks) {
  const auto& entries = rwcalc::i18n_detail::russian_entries();
  ASSERT_GT(entries.size(), 250U);
  for (const auto& e : entries) {
    EXPECT_EQ(field_problem(e.id, e.text), "") << e.id;
    EXPECT_EQ(std::count(e.id.begin(), e.id.end(), '\n'), std::count(e.text.begin(), e.text.end(), '\n')) << e.id;
    // A message that starts or ends with a space or a line break is a piece of a longer text.
    EXPECT_EQ(e.id.front() == ' ', e.text.front() == ' ') << e.id;
    EXPECT_EQ(e.id.back() == '\n', e.text.back() == '\n') << e.id;
  }
}

TEST(Catalogue, ReadsContinuationLinesEscapesAndSkipsFuzzyAndObsoleteEntries) {
  const auto e = rwcalc::i18n_detail::parse_po(
      "msgid \"\"\nmsgstr \"Language: ru\\n\"\n\n"
      "#: a.cpp:1\nmsgid \"\"\n\"two \\\"lines\\\"\\n\"\n\"end\"\nmsgstr \"\"\n\"две\\n\"\n\"конец\\\\\"\n\n"
      "#, fuzzy\nmsgid \"guess\"\nmsgstr \"догадка\"\n\n"
      "msgid \"untranslated\"\nmsgstr \"\"\n\n"
      "#~ msgid \"old\"\n#~ msgstr \"старое\"\n");
  ASSERT_EQ(e.size(), 1U);
  EXPECT_EQ(e[0].id, "two \"lines\"\nend");
  EXPECT_EQ(e[0].text, "две\nконец\\");
}

TEST(Catalogue, TranslatesOnlyInRussianAndFallsBackToEnglish) {
  constexpr const char* table = "Table {}";
  EXPECT_STREQ(rwcalc::tr(table), table);
  const LanguageScope ru(Language::Russian);
  EXPECT_STREQ(rwcalc::tr(table), "Таблица {}");
  EXPECT_EQ(rwcalc::trf(table, 2), "Таблица 2");
  EXPECT_STREQ(rwcalc::tr("a text not in the catalogue"), "a text not in the catalogue");
  EXPECT_STREQ(rwcalc::language_code(), "ru");
}

TEST(Language, ParsesCodesAndLocaleNames) {
  EXPECT_EQ(rwcalc::parse_language("ru"), Language::Russian);
  EXPECT_EQ(rwcalc::parse_language("ru_RU.UTF-8"), Language::Russian);
  EXPECT_EQ(rwcalc::parse_language("en_GB.UTF-8"), Language::English);
  EXPECT_EQ(rwcalc::parse_language("C"), Language::English);
  EXPECT_FALSE(rwcalc::parse_language("de"));
}

TEST(DecimalComma, NumbersOnTheirOwnOnlyAndNeverInEnglish) {
  const std::string text = "N 0.000849 ± 2.1e-05 °/h [0.1, 0.2] P=0.93/0.05 -1.5 rwcalc 0.1.0 gl2d_0.5C.csv v2.5 1, 2";
  EXPECT_EQ(localize_numbers(text), text);
  const LanguageScope ru(Language::Russian);
  EXPECT_EQ(localize_numbers(text),
            "N 0,000849 ± 2,1e-05 °/h [0,1; 0,2] P=0,93/0,05 -1,5 rwcalc 0.1.0 gl2d_0.5C.csv v2.5 1, 2");
  EXPECT_EQ(localize_numbers("ends 3.5.\nx.5 a.b 7.25"), "ends 3,5.\nx.5 a.b 7,25");
}

TEST(DecimalComma, HtmlTextOnlyNotMarkupStylesOrScripts) {
  const std::string page =
      "<style>p { margin: 0.5em; }</style><p style=\"width: 1.5em\">σ = 0.25 °/h</p>"
      "<script>var x = 2.5;</script><img alt=\"0.5\"/>1.25";
  const LanguageScope ru(Language::Russian);
  EXPECT_EQ(localize_html(page),
            "<style>p { margin: 0.5em; }</style><p style=\"width: 1.5em\">σ = 0,25 °/h</p>"
            "<script>var x = 2.5;</script><img alt=\"0.5\"/>1,25");
}

TEST(RussianCli, BatchPrintsThePapersTablesInRussianWithRussianUnits) {
  const auto r = run_cli(rwcalc::test::concat({"batch", "--lang", "ru"}, rwcalc::test::gl2d_runs()));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part : {"Таблица 1.", "Таблица 2.", "N (ВА), °/√ч", "B (ВА), °/ч", "N прямой, °/√ч",
                           "B осредн. 100 с, °/ч", "класс", "Итог по всем запускам", "по N", "по B"})
    EXPECT_TRUE(contains(r.out, part)) << part << "\n" << r.out;
  for (const char* english : {"Table 1", "Table 2", "Overall over the runs", "deg/h", "class table", "°/h"})
    EXPECT_FALSE(contains(r.out, english)) << english << "\n" << r.out;
  // Decimal comma in the table (N by the fit of the −50 °C run is 0.000851 °/√h), no decimal point.
  EXPECT_TRUE(contains(r.out, "0,000851")) << r.out;
  EXPECT_FALSE(std::regex_search(r.out, std::regex(R"(\b\d+\.\d+\b)"))) << r.out;
}

TEST(RussianCli, EnvironmentChoosesTheLanguageAndEnglishStaysTheDefault) {
  const auto args = rwcalc::test::concat({"batch"}, rwcalc::test::gl2d_runs());
  const auto english = run_cli(args);
  ASSERT_EQ(english.status, 0);
  EXPECT_TRUE(contains(english.out, "Table 1: coefficients"));
  EXPECT_EQ(run_cli(rwcalc::test::concat({"batch", "--lang", "en"}, rwcalc::test::gl2d_runs())).out, english.out);
  ::setenv("RWCALC_LANG", "ru_RU.UTF-8", 1);
  const auto russian = run_cli(args);
  const auto forced = run_cli(rwcalc::test::concat({"batch", "--lang", "en"}, rwcalc::test::gl2d_runs()));
  ::unsetenv("RWCALC_LANG");
  EXPECT_TRUE(contains(russian.out, "Таблица 1.")) << russian.out;
  EXPECT_EQ(forced.out, english.out);         // --lang wins over the environment
  EXPECT_EQ(run_cli(args).out, english.out);  // and nothing stays behind in the process
}

TEST(RussianCli, JsonAndCsvKeepTheirKeysAndTheDecimalPoint) {
  const auto file = rwcalc::test::gl2d_runs().front();
  const auto en = run_cli({"analyze", "--json", file});
  const auto ru = run_cli({"analyze", "--json", "--lang", "ru", file});
  ASSERT_EQ(ru.status, 0) << ru.err;
  auto a = nlohmann::json::parse(en.out), b = nlohmann::json::parse(ru.out);
  // Keys, codes and numbers are the same; free text (statements, the fit range's reason) is in
  // the chosen language.
  EXPECT_NE(a["fit"]["range"]["reason"], b["fit"]["range"]["reason"]);
  a["fit"]["range"].erase("reason");
  b["fit"]["range"].erase("reason");
  EXPECT_EQ(a["fit"], b["fit"]);
  EXPECT_EQ(a["verdict"]["class"], b["verdict"]["class"]);
  EXPECT_EQ(a["methods"], b["methods"]);
  EXPECT_EQ(a["verdict"]["p_is"], b["verdict"]["p_is"]);
  const auto csv_en = run_cli(rwcalc::test::concat({"batch", "--csv"}, rwcalc::test::gl2d_runs()));
  const auto csv_ru = run_cli(rwcalc::test::concat({"batch", "--csv", "--lang", "ru"}, rwcalc::test::gl2d_runs()));
  EXPECT_EQ(csv_en.out, csv_ru.out);
}

TEST(RussianCli, AnalyzeTextAndErrorsInRussian) {
  const auto r = run_cli({"analyze", "--lang", "ru", rwcalc::test::gl2d_runs().front()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part : {"Данные", "Коэффициенты шумов", "Проверка методами статьи", "Заключение", "°/√ч"})
    EXPECT_TRUE(contains(r.out, part)) << part;
  const auto bad = run_cli({"analyze", "--lang", "ru", "/nonexistent/run.csv"});
  EXPECT_NE(bad.status, 0);
  EXPECT_TRUE(bad.err.starts_with("rwcalc: ошибка: ")) << bad.err;
  const auto wrong = run_cli({"analyze", "--lang", "de", rwcalc::test::gl2d_runs().front()});
  EXPECT_EQ(wrong.status, 2);
}

TEST(RussianCli, ReportIsInRussianWithoutEnglishHeadings) {
  TempDir dir;
  auto args = rwcalc::test::concat({"report", "--lang", "ru", "--no-figures", "--lab", "Лаборатория 1", "-o",
                                    dir.path().string()},
                                   rwcalc::test::gl2d_runs());
  const auto r = run_cli(args);
  ASSERT_EQ(r.status, 0) << r.err;
  const auto html = slurp(dir.path() / "report.html");
  for (const char* part :
       {"<html lang=\"ru\">", "вариации Аллана", "случайное блуждание угла", "нестабильность смещения нуля",
        "случайное блуждание скорости", "класс точности БИНС по ГОСТ РВ 52339-2005", "Таблица 1.", "Таблица 2.", "°/ч",
        "°/√ч", "угл. с", "Лаборатория 1", "Страница", "с вероятностью"})
    EXPECT_TRUE(contains(html, part)) << part;
  for (const char* english : {"lang=\"en\"",
                              "Table 1",
                              "Table 2",
                              "Verdict",
                              "Runs",
                              "Settings and conventions",
                              "Noise coefficients",
                              "Accuracy class per parameter",
                              "Data and identification",
                              "Allan-variance fit",
                              "angle random walk",
                              "bias instability",
                              "rate random walk",
                              "quantization",
                              "temperature",
                              "Warnings",
                              "Figure",
                              "°/h",
                              "Generated by",
                              "upper bound",
                              "with a probability",
                              "sigma^2",
                              "Page"})
    EXPECT_FALSE(contains(html, english)) << english;
}

TEST(Catalogue, EveryUnitLabelAndTermNameOfEverySensorHasItsRussianEntry) {
  using rwcalc::SensorKind;
  std::vector<rwcalc::UnitSet> sets{rwcalc::si_units(SensorKind::Gyro), rwcalc::si_units(SensorKind::Accelerometer)};
  for (const char* u : {"", "deg/h", "deg/s", "rad/s"}) sets.push_back(rwcalc::output_units(SensorKind::Gyro, u));
  for (const char* u : {"", "m/s^2", "g", "mg", "ug"})
    sets.push_back(rwcalc::output_units(SensorKind::Accelerometer, u));
  for (const auto& set : sets) {
    EXPECT_TRUE(in_catalogue(set.deviation.label)) << set.deviation.label;
    for (const auto& u : set.term) EXPECT_TRUE(in_catalogue(u.label)) << u.label;
  }
  for (const SensorKind k : {SensorKind::Gyro, SensorKind::Accelerometer})
    for (const rwcalc::Term t : rwcalc::kAllTerms) {
      EXPECT_TRUE(in_catalogue(std::string(rwcalc::term_meaning(k, t)))) << rwcalc::term_meaning(k, t);
      const LanguageScope ru(Language::Russian);
      EXPECT_NE(rwcalc::localized_meaning(k, t), rwcalc::term_meaning(k, t));
    }
}

TEST(RussianCli, ImuTablesInThePapersTermsAndRussianUnits) {
  TempDir dir;
  const auto file = dir.write("imu.csv", imu_csv());
  const auto r = run_cli(imu_args(file, {"--lang", "ru"}));
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part :
       {"Данные", "Гироскопы (осей: 3", "Акселерометры (осей: 3", "случайное блуждание угла",
        "нестабильность смещения нуля", "случайное блуждание скорости", "случайное блуждание линейной скорости",
        "случайное блуждание ускорения", "N в °/√ч", "B в °/ч", "Q в угл. с", "N в м/с/√ч", "B в мкg", "N в рад/с/√Гц",
        "N в м/с²/√Гц", "среднее", "τ аппроксимации (с)", "Обозначения"})
    EXPECT_TRUE(contains(r.out, part)) << part << "\n" << r.out;
  for (const char* english : {"Data\n",
                              "samples at",
                              "Gyro",
                              "Accelerometer",
                              "axes;",
                              "angle random walk",
                              "bias instability",
                              "rate random walk",
                              "velocity random walk",
                              "quantisation",
                              "mean",
                              "N in",
                              "fit chi2",
                              "fit tau",
                              "°/h",
                              "m/s/√h",
                              "µg",
                              "√Hz",
                              "rad/s",
                              "Earth rate",
                              "class verdict",
                              "Conventions",
                              "profile intervals"})
    EXPECT_FALSE(contains(r.out, english)) << english << "\n" << r.out;
  EXPECT_FALSE(std::regex_search(r.out, std::regex(R"((^|[^\w.])\d+\.\d+\b)"))) << r.out;  // decimal comma
}

TEST(RussianCli, BadInputIsNamedInRussian) {
  TempDir dir;
  const auto bad = dir.write("bad.csv", "# rate_hz: 100\npulses,x\n1,2\n3\n");
  const auto r = run_cli({"analyze", "--lang", "ru", "--column", "pulses", bad.string()});
  EXPECT_EQ(r.status, 2);
  EXPECT_TRUE(contains(r.err, "неверное число столбцов: ожидается 2")) << r.err;
  const auto en = run_cli({"analyze", "--column", "pulses", bad.string()});
  EXPECT_TRUE(contains(en.err, "wrong number of columns: expected 2")) << en.err;
  const auto unit = run_cli({"imu", "--lang", "ru", bad.string(), "--gyro", "pulses", "--output-unit", "furlong"});
  EXPECT_TRUE(contains(unit.err, "неизвестная единица вывода 'furlong'")) << unit.err;
}

TEST(RussianCli, AccelerometerChannelInRussianUnits) {
  TempDir dir;
  const auto file = dir.write("imu.csv", imu_csv());
  const auto r = run_cli({"analyze", "--lang", "ru", "--rate", "100", "--column", "acc_x_g", file.string()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part : {"rwcalc, акселерометр:", "Данные", "случайное блуждание линейной скорости",
                           "случайное блуждание ускорения", "м/с/√ч", "мкg", "м/с²/√Гц", "Коэффициенты шумов"})
    EXPECT_TRUE(contains(r.out, part)) << part << "\n" << r.out;
  for (const char* english : {"accelerometer", "Data", "velocity", "µg", "m/s", "Hz", "Noise coefficients", "tau"})
    EXPECT_FALSE(contains(r.out, english)) << english << "\n" << r.out;
}

TEST(RussianCli, ImuJsonReportAndNoiseFile) {
  TempDir dir;
  const auto file = dir.write("imu.csv", imu_csv());
  const auto en = run_cli(imu_args(file, {"--json", "--kalibr", (dir.path() / "en.yaml").string()}));
  const auto ru = run_cli(imu_args(file, {"--json", "--lang", "ru", "--kalibr", (dir.path() / "ru.yaml").string()}));
  ASSERT_EQ(ru.status, 0) << ru.err;
  auto a = nlohmann::json::parse(en.out), b = nlohmann::json::parse(ru.out);
  // Keys, numbers, units and the terms' names stay English; free text (the fit range's reason, why
  // no verdict, the verdict's statements, the input notes) is in the chosen language.
  for (auto* j : {&a, &b})
    for (auto& c : (*j)["channels"]) {
      c["fit"]["range"].erase("reason");
      c.erase("not_applied_reason");
      c["input"].erase("notes");
      if (c["verdict"].is_object())
        for (const char* k : {"statement", "statement_B", "statement_N"}) c["verdict"].erase(k);
    }
  EXPECT_EQ(a["channels"], b["channels"]);
  EXPECT_EQ(a["noise"], b["noise"]);
  // The noise file is read by Kalibr: the same bytes in every language.
  EXPECT_EQ(slurp(dir.path() / "en.yaml"), slurp(dir.path() / "ru.yaml"));
  EXPECT_TRUE(contains(ru.err, "файл шумов записан в")) << ru.err;
  const auto report = dir.path() / "report";
  ASSERT_EQ(run_cli(imu_args(file, {"--lang", "ru", "--report", report.string()})).status, 0);
  const auto html = slurp(report / "index.html");
  for (const char* part : {"<html lang=\"ru\">", "<h1>Шумы инерциального измерительного блока", "Оси гироскопов",
                           "Файл шумов", "Таблица 2", "°/√ч", "Страница"})
    EXPECT_TRUE(contains(html, part)) << part;
  for (const char* english : {"IMU noise", "Noise file", "All results", "Gyro", "angle random walk", "°/h", "Page"})
    EXPECT_FALSE(contains(html, english)) << english;
  // The figures' titles and axes (the gnuplot script needs no gnuplot).
  const auto script = dir.path() / "imu.gp";
  ASSERT_EQ(run_cli(imu_args(file, {"--lang", "ru", "--plot-script", script.string(), "-o", "/dev/null"})).status, 0);
  const auto gp = slurp(script);
  for (const char* part : {"Оси гироскопов: imu.csv", "Оси акселерометров: imu.csv", "девиация Аллана σ(τ) (°/ч)",
                           "девиация Аллана σ(τ) (мкg)", "τ (с)"})
    EXPECT_TRUE(contains(gp, part)) << part;
  for (const char* english : {"Gyro axes", "Accelerometer axes", "Allan deviation", "µg", "°/h"})
    EXPECT_FALSE(contains(gp, english)) << english;
}

TEST(RussianCli, HelpIsRussianUnderLangAndTheManualStaysEnglish) {
  const auto imu = run_cli({"imu", "--help", "--lang", "ru"});
  ASSERT_EQ(imu.status, 0) << imu.err;
  for (const char* part : {"Использование: rwcalc imu [ПАРАМЕТРЫ] FILE", "Позиционные аргументы:", "Параметры:",
                           "Вывести эту справку и выйти", "Вход:", "Вывод:", "Рисунки:", "Столбцы гироскопов",
                           "Единица столбцов акселерометров", "Язык текста"})
    EXPECT_TRUE(contains(imu.out, part)) << part << "\n" << imu.out;
  for (const char* english : {"Usage:", "Options:", "Positionals:", "Print this help",
                              "Input:", "Output:", "Figures:", "Gyro columns", "Recording", "REQUIRED"})
    EXPECT_FALSE(contains(imu.out, english)) << english << "\n" << imu.out;
  // No command's help keeps an English sentence (three English words in a row).
  const std::regex english_words("[a-z]{3,} [a-z]{3,} [a-z]{3,}");
  for (const char* cmd : {"allan", "analyze", "batch", "merge", "simulate", "diagnose", "imu", "report"}) {
    const auto r = run_cli({cmd, "--help", "--lang", "ru"});
    EXPECT_EQ(r.status, 0) << cmd;
    std::smatch m;
    EXPECT_FALSE(std::regex_search(r.out, m, english_words)) << cmd << ": " << m.str();
  }
  // RWCALC_LANG chooses the help's language too; the manual and the completion stay English.
  const auto man = run_cli({"man"}), completion = run_cli({"completion"});
  const auto english_help = run_cli({"--help"});
  ::setenv("RWCALC_LANG", "ru", 1);
  const auto help = run_cli({"--help"});
  const auto man_ru = run_cli({"man"}), completion_ru = run_cli({"completion"});
  ::unsetenv("RWCALC_LANG");
  EXPECT_TRUE(contains(help.out, "Команды:")) << help.out;
  EXPECT_TRUE(contains(english_help.out, "Subcommands:")) << english_help.out;
  EXPECT_EQ(man_ru.out, man.out);
  EXPECT_EQ(completion_ru.out, completion.out);
  EXPECT_TRUE(contains(man.out, "Print the manual page"));
}

TEST(RussianCli, AllanHeaderAndInputNotesInRussian) {
  const auto r = run_cli({"allan", "--lang", "ru", "--tau", "decade", rwcalc::test::gl2d_runs().front()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part : {"# вход: столбец 'pulses': счёт импульсов, 0,92 угл. с на импульс",
                           "# оценка: перекрывающаяся девиация Аллана (oadev)", "(метаданные)"})
    EXPECT_TRUE(contains(r.out, part)) << part << "\n" << r.out;
  for (const char* english : {"# input:", "deviation", "arcsec per", "metadata"})
    EXPECT_FALSE(contains(r.out, english)) << english << "\n" << r.out;
  const auto mdev = run_cli({"allan", "--lang", "ru", "--estimator", "mdev", rwcalc::test::gl2d_runs().front()});
  EXPECT_TRUE(contains(mdev.out, "# оценка: модифицированная девиация Аллана (mdev)")) << mdev.out;
  // A rate column: the notes on how it was read and why no verdict is given.
  TempDir dir;
  const auto file = dir.write("imu.csv", imu_csv());
  const auto a = run_cli({"analyze", "--lang", "ru", "--rate", "100", "--column", "gyro_x_dps", file.string()});
  ASSERT_EQ(a.status, 0) << a.err;
  EXPECT_TRUE(contains(a.err, "вход rate определён по имени столбца 'gyro_x_dps'")) << a.err;
  EXPECT_TRUE(contains(a.err, "единица скорости deg/s взята из имени столбца")) << a.err;
  EXPECT_FALSE(contains(a.err, "from the column name")) << a.err;
  EXPECT_TRUE(contains(a.out, "а не импульсы лазерного гироскопа")) << a.out;
  EXPECT_FALSE(contains(a.out, "ring-laser")) << a.out;
  const auto bad = run_cli({"analyze", "--lang", "ru", "--rate", "-1", file.string()});
  EXPECT_EQ(bad.status, 2);
  EXPECT_TRUE(contains(bad.err, "вне допустимого диапазона")) << bad.err;
}

TEST(RussianCli, DiagnosisInRussian) {
  const auto r = run_cli({"diagnose", "--lang", "ru", "--runs", "10", rwcalc::test::gl2d_runs().back()});
  ASSERT_EQ(r.status, 0) << r.err;
  for (const char* part : {"Диагностика ", "Базовая модель", "Детекторы", "Находки:", "Расширенная модель",
                           "счёт импульсов не может пройти через фильтр выходного тракта", " с)"})
    EXPECT_TRUE(contains(r.out, part)) << part << "\n" << r.out;
  for (const char* english : {"Diagnosis of", "Findings", "not found", "statistic", "threshold", "pulse counts cannot",
                              "Extended model", " s)"})
    EXPECT_FALSE(contains(r.out, english)) << english << "\n" << r.out;
}

TEST(RussianCli, CommandLineErrorsInRussianAndUnchangedInEnglish) {
  const auto extra = run_cli({"analyze", "--lang", "ru", rwcalc::test::gl2d_runs().front(), "surplus"});
  EXPECT_EQ(extra.status, 2);
  EXPECT_TRUE(contains(extra.err, "неожиданный аргумент: surplus")) << extra.err;
  const auto missing = run_cli({"analyze", "--lang", "ru"});
  EXPECT_EQ(missing.status, 2);
  EXPECT_TRUE(contains(missing.err, "требуется FILE")) << missing.err;
  EXPECT_FALSE(contains(missing.err, "is required")) << missing.err;
  const auto english = run_cli({"analyze"});
  EXPECT_TRUE(contains(english.err, "FILE is required")) << english.err;
}

TEST(ReportPdf, WithoutChromiumTheHtmlIsWrittenAndTheMissingPdfSaid) {
  TempDir dir;
  const std::string path = std::getenv("PATH") ? std::getenv("PATH") : "";
  ::setenv("PATH", dir.path().c_str(), 1);  // a directory with no browser in it
  ::unsetenv("RWCALC_CHROMIUM");
  const auto r = run_cli(
      {"report", "--pdf", "--no-figures", "-o", (dir.path() / "out").string(), rwcalc::test::gl2d_runs().front()});
  ::setenv("PATH", path.c_str(), 1);
  EXPECT_EQ(r.status, 3) << r.err;  // an output asked for and not made
  EXPECT_TRUE(std::filesystem::exists(dir.path() / "out" / "report.html"));
  EXPECT_FALSE(std::filesystem::exists(dir.path() / "out" / "report.pdf"));
  EXPECT_TRUE(contains(r.err, "no headless Chromium found")) << r.err;
}

TEST(ReportPdf, PrintedByHeadlessChromiumWhenInstalled) {
  if (std::system("command -v chromium >/dev/null 2>&1") != 0) GTEST_SKIP() << "no chromium in PATH";
  TempDir dir;
  // A title with shell metacharacters: the browser is run from an argument vector, never a shell.
  const auto out = dir.path() / "out $(touch pwned) ; 'x'";
  const auto r = run_cli({"report", "--lang", "ru", "--pdf", "--no-figures", "--title", "`touch pwned2`", "-o",
                          out.string(), rwcalc::test::gl2d_runs().front()});
  ASSERT_EQ(r.status, 0) << r.err;
  const std::string pdf = slurp(out / "report.pdf");
  ASSERT_GT(pdf.size(), 1000U);
  EXPECT_TRUE(pdf.starts_with("%PDF-"));
  EXPECT_FALSE(std::filesystem::exists("pwned"));
  EXPECT_FALSE(std::filesystem::exists("pwned2"));
  EXPECT_TRUE(contains(r.out, "PDF записан в")) << r.out;
  // Written again only with --force.
  const auto again =
      run_cli({"report", "--pdf", "--no-figures", "-o", out.string(), rwcalc::test::gl2d_runs().front()});
  EXPECT_EQ(again.status, 3) << again.err;
}
