#pragma once
// The "C" numeric locale for the replay's text: numbers are read and written with a '.'
// whatever locale the process runs in (in Python, locale.setlocale(LC_ALL, '') under de_DE
// made the CSV's numbers '0,199000', their commas read as column separators).

#include <locale.h>

namespace cf::internal {

/// The process's "C" numeric locale object.
inline locale_t c_numeric() {
  static const locale_t c = newlocale(LC_NUMERIC_MASK, "C", static_cast<locale_t>(nullptr));
  return c;
}

/// This thread formats in the C numeric locale while it lives.
class CNumericScope {
 public:
  CNumericScope() : old_(uselocale(c_numeric())) {}
  ~CNumericScope() { uselocale(old_); }
  CNumericScope(const CNumericScope&) = delete;
  CNumericScope& operator=(const CNumericScope&) = delete;

 private:
  locale_t old_;
};

}  // namespace cf::internal
