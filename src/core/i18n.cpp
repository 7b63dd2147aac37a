// The message catalogue: po/ru.po compiled in (generated/catalog_ru.cpp), read once on first use.
#include "rwcalc/i18n.hpp"

#include <algorithm>
#include <atomic>
#include <cctype>
#include <unordered_map>
#include <utility>

#include "rwcalc/printable.hpp"

namespace rwcalc {

std::string_view embedded_russian_po();  // generated from po/ru.po by cmake/catalog.cmake

namespace {

std::atomic<Language> g_language{Language::English};

/// The unit labels of units.hpp (one place for every sensor), translated where they are shown.
[[maybe_unused]] constexpr const char* kUnitLabels[] = {N_("°/h"),  N_("°/√h"), N_("°/h/√h"),
                                                        N_("°/h²"), N_("″"),    N_("″²")};

/// The body of a quoted .po string with its C escapes resolved ("" when the line holds none).
std::string unquote(std::string_view line) {
  const auto open = line.find('"');
  const auto close = line.rfind('"');
  if (open == std::string_view::npos || close <= open) return {};
  std::string out;
  for (std::size_t i = open + 1; i < close; ++i) {
    if (line[i] != '\\' || i + 1 >= close) {
      out += line[i];
      continue;
    }
    switch (const char c = line[++i]) {
      case 'n': out += '\n'; break;
      case 't': out += '\t'; break;
      default: out += c;  // \" and \\ and anything else: the character itself
    }
  }
  return out;
}

struct Catalogue {
  std::vector<i18n_detail::Entry> entries;
  std::unordered_map<std::string, std::string> russian;
  std::unordered_map<std::string, std::vector<std::string>> russian_plurals;  ///< by the singular msgid
  Catalogue() : entries(i18n_detail::parse_po(embedded_russian_po())) {
    for (const auto& e : entries) {
      if (e.plural_id.empty())
        russian.emplace(e.id, e.text);
      else
        russian_plurals.emplace(e.id, e.forms);
    }
  }
};

const Catalogue& catalogue() {
  static const Catalogue c;  // thread-safe initialisation
  return c;
}

/// The marks of as_typed(): U+FDD0 and U+FDD1 in UTF-8.
constexpr std::string_view kTypedOpen = "\xEF\xB7\x90", kTypedClose = "\xEF\xB7\x91";

/// Where the text marked as typed that starts at `open` ends (after its closing mark), at most `to`.
std::size_t typed_end(const std::string& t, std::size_t open, std::size_t to) {
  const std::size_t close = t.find(kTypedClose, open + kTypedOpen.size());
  return close == std::string::npos || close >= to ? to : close + kTypedClose.size();
}

/// `t` without the marks of as_typed().
void remove_typed_marks(std::string& t) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < t.size();) {
    if (t.compare(i, kTypedOpen.size(), kTypedOpen) == 0 || t.compare(i, kTypedClose.size(), kTypedClose) == 0) {
      i += kTypedOpen.size();
      continue;
    }
    t[out++] = t[i++];
  }
  t.resize(out);
}

bool word_byte(char c) { return std::isalnum(static_cast<unsigned char>(c)) || c == '_'; }
bool digit(char c) { return std::isdigit(static_cast<unsigned char>(c)) != 0; }

/// Where a decimal number standing alone starts at i: not inside a word, a name or a version.
bool number_starts(const std::string& t, std::size_t i) {
  if (!digit(t[i])) return false;
  if (i == 0) return true;
  char prev = t[i - 1];
  if ((prev == '-' || prev == '+') && i >= 2) prev = t[i - 2];  // a sign
  return !word_byte(prev) && prev != '.' && prev != '\\';
}

/// The end of the number starting at i and whether it has a fractional part (at `point`).
std::size_t number_end(const std::string& t, std::size_t i, std::size_t& point) {
  point = std::string::npos;
  while (i < t.size() && digit(t[i])) ++i;
  if (i + 1 < t.size() && t[i] == '.' && digit(t[i + 1])) {
    point = i++;
    while (i < t.size() && digit(t[i])) ++i;
  }
  if (i + 1 < t.size() && (t[i] == 'e' || t[i] == 'E')) {
    std::size_t j = i + 1;
    if (j < t.size() && (t[j] == '-' || t[j] == '+')) ++j;
    if (j < t.size() && digit(t[j])) {
      while (j < t.size() && digit(t[j])) ++j;
      i = j;
    }
  }
  return i;
}

/// Followed by a letter or by ".x" (a version, a file extension): not a number on its own.
bool number_ends_alone(const std::string& t, std::size_t end) {
  if (end >= t.size()) return true;
  if (word_byte(t[end])) return false;
  return !(t[end] == '.' && end + 1 < t.size() && word_byte(t[end + 1]));
}

/// Rewrite t[from, to) in place: decimal points of numbers to commas, and ", " between two numbers
/// of which one has a decimal comma to "; " (so that "[0,1; 0,2]" stays readable).
void localize_span(std::string& t, std::size_t from, std::size_t to) {
  bool last_had_point = false;
  std::size_t last_end = std::string::npos;
  for (std::size_t i = from; i < to;) {
    if (t.compare(i, kTypedOpen.size(), kTypedOpen) == 0) {  // outside text: as typed
      i = typed_end(t, i, to);
      last_end = std::string::npos;
      continue;
    }
    if (!number_starts(t, i)) {
      ++i;
      continue;
    }
    std::size_t point = 0;
    const std::size_t end = number_end(t, i, point);
    if (!number_ends_alone(t, end)) {
      i = end;
      while (i < to && (word_byte(t[i]) || t[i] == '.')) ++i;  // skip the rest of the name
      last_end = std::string::npos;
      continue;
    }
    const bool has_point = point != std::string::npos;
    if (has_point) t[point] = ',';
    std::size_t start = i;
    if (start > from && (t[start - 1] == '-' || t[start - 1] == '+')) --start;
    if (last_end != std::string::npos && start == last_end + 2 && t[last_end] == ',' && t[last_end + 1] == ' ' &&
        (has_point || last_had_point))
      t[last_end] = ';';
    last_end = end;
    last_had_point = has_point;
    i = end;
  }
}

}  // namespace

std::optional<Language> parse_language(std::string_view name) {
  const auto lang = name.substr(0, name.find_first_of("_.@-"));
  if (lang == "en" || lang == "C" || lang == "POSIX") return Language::English;
  if (lang == "ru") return Language::Russian;
  return std::nullopt;
}

Language language() { return g_language.load(std::memory_order_relaxed); }
void set_language(Language lang) { g_language.store(lang, std::memory_order_relaxed); }
const char* language_code() { return language() == Language::Russian ? "ru" : "en"; }

const char* tr(const char* english) {
  if (language() == Language::English) return english;
  const auto& map = catalogue().russian;
  const auto it = map.find(english);
  return it == map.end() ? english : it->second.c_str();
}

std::string tr(const std::string& english) { return tr(english.c_str()); }

int russian_plural_form(unsigned long long n) {
  // The catalogue's Plural-Forms: one (1, 21, 101…), few (2–4, 22–24…), many (the rest, 11–14 too).
  if (n % 10 == 1 && n % 100 != 11) return 0;
  if (n % 10 >= 2 && n % 10 <= 4 && (n % 100 < 10 || n % 100 >= 20)) return 1;
  return 2;
}

const char* trn(const char* singular, const char* plural, unsigned long long n) {
  if (language() == Language::English) return n == 1 ? singular : plural;
  const auto& map = catalogue().russian_plurals;
  const auto it = map.find(singular);
  const auto form = static_cast<std::size_t>(russian_plural_form(n));
  if (it == map.end() || form >= it->second.size()) return n == 1 ? singular : plural;
  return it->second[form].c_str();
}

std::string marked_as_typed(std::string_view encoded) {
  std::string s;
  s.reserve(encoded.size() + kTypedOpen.size() + kTypedClose.size());
  return s.append(kTypedOpen).append(encoded).append(kTypedClose);
}

std::string as_typed(std::string_view outside) { return marked_as_typed(printable(outside)); }

std::string localize_numbers(std::string text) {
  if (language() == Language::Russian) localize_span(text, 0, text.size());
  remove_typed_marks(text);
  return text;
}

std::string localize_message(std::string_view text) {
  std::string shown;
  for (std::size_t at = 0; at < text.size();) {
    const std::size_t open = std::min(text.find(kTypedOpen, at), text.size());
    shown += printable(text.substr(at, open - at));
    if (open == text.size()) break;
    const std::size_t inside = open + kTypedOpen.size();
    const std::size_t close = std::min(text.find(kTypedClose, inside), text.size());
    shown += as_typed(text.substr(inside, close - inside));
    at = std::min(close + kTypedClose.size(), text.size());
  }
  return localize_numbers(std::move(shown));
}

std::string localize_html(std::string html) {
  if (language() != Language::Russian) {
    remove_typed_marks(html);
    return html;
  }
  std::size_t i = 0;
  while (i < html.size()) {
    const std::size_t tag = html.find('<', i);
    localize_span(html, i, tag == std::string::npos ? html.size() : tag);
    if (tag == std::string::npos) break;
    // Element content of <style> and <script> is not text: skip to its closing tag.
    std::size_t after = html.find('>', tag);
    if (after == std::string::npos) break;
    for (const char* raw : {"<style", "<script"})
      if (html.compare(tag, std::string_view(raw).size(), raw) == 0) {
        const auto close = html.find(std::string("</") + (raw + 1), after);
        after = close == std::string::npos ? html.size() - 1 : html.find('>', close);
      }
    i = after + 1;
  }
  remove_typed_marks(html);
  return html;
}

namespace i18n_detail {

const std::vector<Entry>& russian_entries() { return catalogue().entries; }

std::vector<Entry> parse_po(std::string_view po) {
  std::vector<Entry> out;
  std::string id, text, plural_id, *field = nullptr;
  std::vector<std::string> forms;
  bool fuzzy = false, next_fuzzy = false;
  auto finish = [&] {
    // A plural entry counts when every form is translated; its first form stands as its text.
    const bool complete = plural_id.empty() ? !text.empty()
                                            : !forms.empty() && std::none_of(forms.begin(), forms.end(),
                                                                             [](const auto& f) { return f.empty(); });
    if (!id.empty() && complete && !fuzzy)
      out.push_back(
          {id, plural_id.empty() ? text : forms.front(), plural_id, plural_id.empty() ? decltype(forms){} : forms});
    id.clear();
    text.clear();
    plural_id.clear();
    forms.clear();
  };
  for (std::size_t at = 0; at < po.size();) {
    std::size_t eol = po.find('\n', at);
    if (eol == std::string_view::npos) eol = po.size();
    const std::string_view line = po.substr(at, eol - at);
    at = eol + 1;
    if (line.starts_with("msgid ")) {
      finish();
      fuzzy = std::exchange(next_fuzzy, false);
      field = &id;
    } else if (line.starts_with("msgid_plural ")) {
      field = &plural_id;
    } else if (line.starts_with("msgstr ")) {
      field = &text;
    } else if (line.starts_with("msgstr[")) {
      forms.emplace_back();
      field = &forms.back();
    } else if (!line.starts_with("\"")) {
      if (line.starts_with("#,") && line.find("fuzzy") != std::string_view::npos) next_fuzzy = true;
      if (!line.starts_with("#~")) continue;  // comments; obsolete entries end the one before
      field = nullptr;
      continue;
    }
    if (field) *field += unquote(line);
  }
  finish();
  return out;
}

}  // namespace i18n_detail

}  // namespace rwcalc
