#pragma once
/// @file i18n.hpp
/// The language of rwcalc's human-readable output: English (the default) or Russian.
///
/// Every message is written in the code in English and passed through tr() (trf() when it is a
/// format string); the Russian text comes from po/ru.po, a GNU gettext catalogue compiled into the
/// program, so that no system locale is needed. JSON and CSV keep their English keys and the
/// decimal point; human-readable text in Russian uses the decimal comma (localize_numbers).
#include <fmt/format.h>

#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rwcalc {

enum class Language { English, Russian };

/// "en" or "ru" (also a locale name such as "ru_RU.UTF-8"); nothing for anything else.
[[nodiscard]] std::optional<Language> parse_language(std::string_view name);
/// The language of the messages and reports (process-wide; English until set).
[[nodiscard]] Language language();
void set_language(Language lang);
/// The HTML lang attribute of the current language ("en", "ru").
[[nodiscard]] const char* language_code();

/// The message in the current language: its catalogue entry, else the English text itself.
/// The pointer stays valid for the life of the program.
[[nodiscard]] const char* tr(const char* english);

/// The same for a text known only at run time (a label read from JSON); a copy, since the
/// argument may be a temporary.
[[nodiscard]] std::string tr(const std::string& english);

/// The form of a message for the count n (GNU gettext's ngettext): English singular for 1 and plural
/// otherwise; Russian by the catalogue's three forms (1 рабочий прогон, 2 прогона, 5 прогонов).
[[nodiscard]] const char* trn(const char* singular, const char* plural, unsigned long long n);
/// Which of the three Russian forms n takes (0: 1, 21, 101; 1: 2–4, 22–24; 2: 0, 5–20, 25…).
[[nodiscard]] int russian_plural_form(unsigned long long n);

/// trn() as a format string, formatted with the arguments (n among them where the text shows it).
template <typename... Args>
[[nodiscard]] std::string trnf(const char* singular, const char* plural, unsigned long long n, Args&&... args) {
  return fmt::format(fmt::runtime(trn(singular, plural, n)), std::forward<Args>(args)...);
}

/// Marks a text for the catalogue where it is defined, translated later where it is shown with
/// tr() (the label of a JSON field, which itself stays English): GNU gettext's N_().
constexpr const char* N_(const char* english) { return english; }

/// fmt::format with a translated format string. The English text is checked against the arguments
/// at compile time (a replacement field without its argument, or of the wrong type, does not
/// compile); the catalogue test checks that each translation has the same replacement fields.
template <typename... Args>
[[nodiscard]] std::string trf(fmt::format_string<Args...> english, Args&&... args) {
  return fmt::format(fmt::runtime(tr(fmt::string_view(english).data())), std::forward<Args>(args)...);
}

/// trf() of one of two messages chosen at run time (a message per case, so that each translates
/// whole), both checked at compile time.
template <typename... Args>
[[nodiscard]] std::string trf_either(bool first, fmt::format_string<Args...> if_first,
                                     fmt::format_string<Args...> otherwise, Args&&... args) {
  const fmt::string_view english = first ? fmt::string_view(if_first) : fmt::string_view(otherwise);
  return fmt::format(fmt::runtime(tr(english.data())), std::forward<Args>(args)...);
}

/// Outside text inside human-readable text (a file or column name, a serial number, an operator,
/// a laboratory), to be shown as typed: printable(outside) between two marks (the noncharacters
/// U+FDD0 and U+FDD1, which printable() never outputs) that localize_numbers, localize_html and
/// localize_message skip and remove. Text holding marks is shown only through one of them, so that
/// a "1.5" in a serial number stays "1.5" in Russian while the numbers rwcalc prints get their
/// decimal comma.
[[nodiscard]] std::string as_typed(std::string_view outside);
/// The marks alone, around text already encoded for its place by an encoder built on printable()
/// (the HTML escape of the report).
[[nodiscard]] std::string marked_as_typed(std::string_view encoded);

/// Human-readable text with the decimal comma when the language asks for it: every decimal
/// number standing alone (not part of a name, a path or a version such as 0.1.0, nor inside the
/// marks of as_typed) is rewritten "3.14" → "3,14"; the marks are removed in every language.
[[nodiscard]] std::string localize_numbers(std::string text);
/// The same for an HTML page: only text between tags, and never inside <style> or <script>.
[[nodiscard]] std::string localize_html(std::string html);
/// A message for standard error: printable(text) outside the marks of as_typed (the text inside
/// is printable already), then localize_numbers. Text from an exception is raw: U+FDD0 and U+FDD1
/// in it are taken for marks, so they can change only where a decimal comma goes.
[[nodiscard]] std::string localize_message(std::string_view text);

/// The language while it lives, the previous one restored after (a command run in-process).
class LanguageScope {
 public:
  explicit LanguageScope(Language lang) : saved_(language()) { set_language(lang); }
  ~LanguageScope() { set_language(saved_); }
  LanguageScope(const LanguageScope&) = delete;
  LanguageScope& operator=(const LanguageScope&) = delete;

 private:
  Language saved_;
};

namespace i18n_detail {
/// The catalogue's entries (msgid → msgstr, untranslated ones left out), for the tests.
struct Entry {
  std::string id, text;                 ///< a plural entry: the singular msgid and the first form
  std::string plural_id = {};           ///< msgid_plural; empty for a message without plural forms
  std::vector<std::string> forms = {};  ///< msgstr[0], msgstr[1], … of a plural entry
};
[[nodiscard]] const std::vector<Entry>& russian_entries();
/// Parse the text of a .po file (msgid/msgstr with their continuation lines and C escapes).
[[nodiscard]] std::vector<Entry> parse_po(std::string_view po);
}  // namespace i18n_detail

}  // namespace rwcalc
