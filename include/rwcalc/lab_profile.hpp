#pragma once
#ifndef RWCALC_USES_REPORT
#error "rwcalc/lab_profile.hpp belongs to the report layer, which this layer may not use (docs/architecture.md)"
#endif
/// @file lab_profile.hpp
/// The laboratory's part of a test protocol, read from a YAML file (`report --lab-profile`): who
/// approves, performs and checks the test, for which customer, by which method, with which
/// measuring instruments and under which ambient conditions. Every key is documented in
/// docs/test-protocol.md; an unknown key is an error (a misspelt key would silently drop a line
/// of the protocol).
#include <optional>
#include <string>
#include <vector>

namespace rwcalc {

struct ProtocolPerson {
  std::string position;  ///< e.g. "Начальник лаборатории"
  std::string name;      ///< e.g. "И. И. Иванов"
};

/// A date of the profile (ISO 2026-11-27 or 27.11.2026 in the file), checked against the calendar.
struct CalendarDate {
  int year = 0, month = 0, day = 0;
};

struct MeasuringInstrument {
  std::string type;                         ///< type and name, e.g. "частотомер Ч3-63"
  std::string serial;                       ///< serial (factory) number
  CalendarDate verified;                    ///< date of the last verification or calibration
  std::optional<CalendarDate> valid_until;  ///< the verification's expiry, when given
  std::string certificate;                  ///< the verification certificate's number, when given
};

/// An ambient condition as a measured quantity: its value, optionally its uncertainty, its unit.
struct AmbientCondition {
  std::string quantity;  ///< e.g. "температура окружающего воздуха"
  double value = 0;
  std::optional<double> uncertainty;  ///< standard uncertainty, in the same unit
  std::string unit;                   ///< e.g. "°C"
};

struct LabProfile {
  std::string laboratory, address, accreditation;
  ProtocolPerson approver, performer, checker;
  std::string customer;
  std::string method;  ///< the test method (методика) the test follows
  std::vector<MeasuringInstrument> instruments;
  std::vector<AmbientCondition> conditions;
};

/// Reads a lab profile. Throws InputError naming the file, the line and what is wrong (not YAML,
/// an unknown key, a missing instrument field, a date that is no date, a value that is no number).
[[nodiscard]] LabProfile read_lab_profile(const std::string& path);

/// A date as the report's language writes it: 27.11.2026 in Russian, 2026-11-27 in English.
[[nodiscard]] std::string date_text(const CalendarDate& date);

}  // namespace rwcalc
