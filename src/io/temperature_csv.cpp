#include "collision_lab/io/temperature_csv.h"

#include <vector>

#include "collision_lab/io/number_text.h"

namespace collision_lab {
namespace io {

namespace {

std::string csvNumber(double value) {
  char text[kNumberTextMax];
  return std::string(text, writeCsvNumber(text, value));
}

std::ofstream openForWriting(const std::string& path) {
  std::ofstream out(path);
  if (!out) throw CannotOpenFile("cannot open '" + path + "' for writing");
  return out;
}

}  // namespace

TemperatureCsv::TemperatureCsv(const std::string& path, const core::Scene& scene)
    : path_(path),
      out_(openForWriting(path)),
      masses_(scene.masses),
      sampler_(scene, core::temperatureStride(scene.size()), [this](const core::TemperatureSample& s) { write(s); }) {}

void TemperatureCsv::write(const core::TemperatureSample& sample) {
  if (!header_written_) {
    header_written_ = true;
    out_ << "# granular temperature T = (1/N) sum m_i (v_i - V)^2 over the N finite masses, V their "
            "centre-of-mass velocity [J = kg m^2/s^2]\n"
         << "# a row at the start, after each impact whose number is a multiple of k = "
         << core::temperatureStride(masses_.size())
         << ", after each collapse and at the last impact; T holds between rows\n"
         << "impacts,time_s,temperature_J\n";
  }
  thinned_.add(sample);
  out_ << sample.impacts << "," << csvNumber(sample.time) << "," << csvNumber(sample.temperature) << "\n";
}

core::SceneVisitors TemperatureCsv::feeding(core::SceneVisitors visitors) {
  const core::ImpactVisitor impact = visitors.impact;
  visitors.impact = [this, impact](const core::ImpactRecord& record) {
    if (impact) impact(record);
    if (const auto& model = record.model) {  // every body's velocity after it, as the run computed it
      const auto& v = model->velocities_after;
      write({record.index, record.time, core::granularTemperature(masses_, {v.begin(), v.end()})});
    } else {
      sampler_.onImpact(record);
    }
  };
  const core::CollapseVisitor collapse = visitors.collapse;
  visitors.collapse = [this, collapse](const core::Collapse& notice) {
    if (collapse) collapse(notice);
    sampler_.onCollapse(notice);
  };
  return visitors;
}

void TemperatureCsv::finish() {
  sampler_.finish();
  const core::HaffFit fit = core::fitHaff(thinned_.samples());
  out_ << "# haff_fit,T(t) = t0 / (1 + t/tau)^2; t0 and tau fitted by least squares on ln T\n";
  if (fit.ok) {
    out_ << "# haff_fit,t0_J," << csvNumber(fit.t0) << "\n# haff_fit,tau_s," << csvNumber(fit.tau)
         << "\n# haff_fit,rms_ln_error," << csvNumber(fit.rms_log_error) << "\n# haff_fit,samples," << fit.samples
         << "\n";
  } else {
    out_ << "# haff_fit,none: fewer than two rows with T > 0, or none after t = 0\n";
  }
  out_.close();
  if (!out_) throw OutputFailed("cannot write to '" + path_ + "'; T(t) is incomplete");
}

}  // namespace io
}  // namespace collision_lab
