#pragma once
// Standard inputs of the kernel benchmarks, made in memory by the simulator (seeded): the +50 °C
// GL-2D run of data/gl2d (2 h at 400 Hz, 2.88 M samples) as exact counts and as pulse-file text.
#include <string>

#include "rwcalc/pulse_writer.hpp"
#include "rwcalc/simulate.hpp"

namespace rwcalc::bench {

inline NoiseModel gl2d_model() {
  NoiseModel m;
  m.arw_deg_per_sqrt_h = 0.00098;
  m.bias_instability_deg_per_h = 0.0081;
  m.earth_rate_deg_per_h = earth_rate_at(55.75);
  m.readout = ReadoutMode::White;
  return m;
}

inline SimulationSettings gl2d_settings(double duration_s = 7200.0) {
  SimulationSettings s;
  s.duration_s = duration_s;
  s.rate_hz = 400.0;
  s.seed = 52339150;
  s.temperature_c = 50.0;
  return s;
}

/// The 2-h record as exact counts (made once, Ensemble path: only the input's size matters here).
inline const PhaseSeries& gl2d_series() {
  static const PhaseSeries p = [] {
    Simulator sim(gl2d_model(), gl2d_settings(), SimulationPath::Ensemble);
    PhaseSeries out;
    sim.run(52339150, out);
    return out;
  }();
  return p;
}

/// The 2-h record as the text of a GL-2D pulse file (~6 MB).
inline const std::string& gl2d_text() {
  static const std::string t =
      format_pulse_file({{"rate_hz", "400"}, {"scale_arcsec_per_pulse", "0.92"}, {"temperature_c", "50"}},
                        gl2d_series());
  return t;
}

}  // namespace rwcalc::bench
