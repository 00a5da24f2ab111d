#include "model/design/design_files.h"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>

#include "model/io/atomic_write.h"

namespace omnical {
namespace {

constexpr double kDesignDegPerRad = 180.0 / M_PI;

void WriteJson(const nlohmann::json& j, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) { out << j.dump(2) << '\n'; });
}

// The achieved laws of one sensor, as design fit's design.json reports them.
nlohmann::json CharacteristicsJson(const CharacteristicReport& r) {
  return {{"rim_omega_deg", r.rim_omega_deg},
          {"rim_theta_deg", r.rim_theta_deg},
          {"rim_h_px", r.rim_h_px},
          {"equidistant_max_px", r.equidistant_max_px},
          {"constant_aspect_max_px", r.constant_aspect_max_px},
          {"equal_area_max_px", r.equal_area_max_px},
          {"viewpoint_spread_mm", r.viewpoint_spread_mm}};
}

// Table 1's names for the normalised parameters, and their lengths in mm.
nlohmann::json ParametersJson(const FitDesign& design, double rim_mm) {
  nlohmann::json normalised, mm;
  for (const auto& [name, value] : NormalisedParameters(design)) normalised[name] = value;
  for (size_t k = 0; k < design.params.size(); ++k)
    mm[design.mm_names[k]] = design.params[k] * std::pow(rim_mm, design.length_powers[k]);
  mm["m_mm"] = design.m * rim_mm;
  mm["rim_radius_mm"] = rim_mm;
  return {{"normalised", normalised}, {"mm", mm}};
}

}  // namespace

void WriteOdeDesignJson(const DesignOdeResult& r, const std::string& path) {
  const OdeDesign& design = r.design;
  nlohmann::json j;
  j["phi0_deg"] = design.phi0_deg;
  j["phi1_deg"] = design.phi1_deg;
  j["fov_deg"] = design.phi1_deg - design.phi0_deg;
  j["max_law_error_rel"] =
      std::isfinite(r.max_law_error_rel) ? nlohmann::json(r.max_law_error_rel) : nlohmann::json("ray missed");
  j["max_law_error_meaning"] =
      "max |ratio - 1| at the reference distance, ratio = traced increment of h over the law's increment, on 100 "
      "intervals of rho from rho0 (0.1 % of the field where rho0 = 0: the tip) to the field's end; rays traced by "
      "omnical through sensor.yaml";
  j["field"] = {{"t_start_mm", design.t_start_mm},
                {"t_end_mm", design.t_end_mm},
                {"rho_end_mm", design.rho_end_mm},
                {"ends_at", design.ended_at_rim ? "mirror rim (t1), inside rho1" : "imager limit rho1"}};
  j["ode"] = {{"solver", "Boost.Odeint runge_kutta_dopri5, dense output"},
              {"tolerance_rel", 1e-13},
              {"steps", design.ode_steps},
              {"profile_samples", design.profile.size()}};
  j["sensor"] = {{"file", "sensor.yaml"}, {"m_mm", r.m_mm}, {"pixel_pitch_mm", r.pixel_pitch_mm}};
  nlohmann::json sensitivity = nlohmann::json::array();
  for (const LawRatioCurve& c : r.law_ratio) {
    const auto [lo, hi] = std::minmax_element(c.ratio.begin(), c.ratio.end());
    sensitivity.push_back({{"distance_mm", c.distance_mm}, {"ratio_min", *lo}, {"ratio_max", *hi}});
  }
  j["distance_sensitivity"] = sensitivity;
  WriteJson(j, path);
}

void WriteLawRatioCsv(const DesignOdeResult& r, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "rho_mm";
    for (const LawRatioCurve& c : r.law_ratio) out << ",ratio_at_" << c.distance_mm << "_mm";
    out << '\n' << std::setprecision(12);
    const LawRatioCurve& reference = r.reference_curve();
    for (size_t i = 0; i < reference.rho_mm.size(); ++i) {
      out << reference.rho_mm[i];
      for (const LawRatioCurve& c : r.law_ratio) out << ',' << c.ratio[i];
      out << '\n';
    }
  });
}

void WriteOdeDesignSensorYaml(const DesignOdeResult& r, const std::string& table_file, const std::string& path) {
  const auto& lens = std::get<Catadioptric<double, TabulatedProfile, PinholeLens>>(r.sensor.model()).lens;
  const int size_px = r.sensor.image_width_px();
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << std::setprecision(15) << "# Designed by omnical design ode (Gächter's reflection ODE); pixel pitch "
        << r.pixel_pitch_mm * 1e3 << " um puts the field's end at 0.49 image widths.\n"
        << "camera: { model: pinhole, image_size: [" << size_px << ", " << size_px << "], fx: " << lens.fx_px
        << ", fy: " << lens.fy_px << ", cx: " << lens.cx_px << ", cy: " << lens.cy_px << ", k1: 0, k2: 0 }\n"
        << "mirror: { profile: tabulated, rim_radius: " << r.design.t_end_mm << ", table: " << table_file << " }\n"
        << "pose:   { m: " << r.m_mm << ", tilt_deg: [0, 0], decenter_mm: [0, 0] }\n";
  });
}

void WriteFitDesignJson(const DesignFitResult& r, const std::string& sensor_file, const std::string& path) {
  nlohmann::json j;
  j["profile"] = r.spec.profile;
  j["characteristic"] = CharacteristicName(r.spec.characteristic);
  j["targets"] = {{"rim_omega_deg", r.spec.rim_omega_deg}, {"rim_theta_deg", r.spec.rim_theta_deg}};
  j["parameters"] = ParametersJson(r.design, r.rim_radius_mm);
  j["achieved"] = CharacteristicsJson(r.achieved);
  j["achieved_meaning"] =
      "measured through sensor.yaml's model (Eq. 4-7 per mirror radius, 1000 samples): max |h - h_law| in px with the "
      "rim at "
      "rim_h_px, for h_law through the origin and the rim point; viewpoint spread = max - min of Eq. 6's z_v";
  if (r.compared) {
    j["compared"] = CharacteristicsJson(*r.compared);
    j["compared"]["file"] = r.compared_source;
  }
  j["solver"] = {{"free_parameters", r.design.free_params},
                 {"residuals", r.design.free_params > 0 ? r.spec.samples : 0},
                 {"iterations", r.design.iterations},
                 {"final_cost", r.design.final_cost},
                 {"report", r.design.solver_report}};
  j["sensor"] = sensor_file;
  WriteJson(j, path);
}

void WriteFitCharacteristicCsv(const DesignFitResult& r, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "x_mm,omega_deg,h_px,h_" << CharacteristicName(r.law) << "_px,viewpoint_z_mm\n" << std::setprecision(12);
    for (const CharacteristicSample& s : r.achieved.samples)
      out << s.x_mm << ',' << s.omega_deg << ',' << s.h_px << ','
          << r.achieved.rim_h_px *
                 LawHeightRatio(r.law, s.omega_deg * M_PI / 180.0, r.achieved.rim_omega_deg * M_PI / 180.0)
          << ',' << s.viewpoint_z_mm << '\n';
  });
}

void WriteCharacteristicsCsv(const CharacterizeResult& r, const std::string& path) {
  WriteFileAtomically(path, [&](std::ostream& out) {
    out << "x_mm,z_mm,omega_deg,theta_deg,beta_deg,gamma_deg,viewpoint_z_mm,h_px,dh_domega_px_per_deg,"
           "delta_w_px,delta_s_px2,aspect_ratio,tangential_curvature_per_mm,sagittal_curvature_per_mm,"
           "t_inf_x_mm,t_inf_z_mm,s_inf_x_mm,s_inf_z_mm,t_near_x_mm,t_near_z_mm,s_near_x_mm,s_near_z_mm,"
           "L_t_inf_mm,L_s_inf_mm,blur_t_px,blur_s_px,blur_t_deg,blur_s_deg,blur_area_deg2,caustic_x_mm,caustic_z_mm\n"
        << std::setprecision(10);
    for (size_t i = 0; i < r.field.size(); ++i) {
      const FieldSample& f = r.field[i];
      const BlurSpot& b = r.blur[i];
      const AxialRayQuantities& q = f.ray;
      out << q.x_mm << ',' << q.z_mm << ',' << q.omega_rad * kDesignDegPerRad << ',' << q.theta_rad * kDesignDegPerRad << ','
          << q.beta_rad * kDesignDegPerRad << ',' << q.gamma_rad * kDesignDegPerRad << ',' << q.viewpoint_z_mm << ',' << f.h_px << ','
          << f.delta_h_px << ',' << f.delta_w_px << ',' << f.delta_s_px2 << ',' << f.aspect_ratio << ','
          << f.tangential_curvature_per_mm << ',' << f.sagittal_curvature_per_mm << ',' << f.tangential_far.x_mm << ','
          << f.tangential_far.z_mm << ',' << f.sagittal_far.x_mm << ',' << f.sagittal_far.z_mm << ','
          << f.tangential_near.x_mm << ',' << f.tangential_near.z_mm << ',' << f.sagittal_near.x_mm << ','
          << f.sagittal_near.z_mm << ',' << f.tangential_far.lens_distance_mm << ',' << f.sagittal_far.lens_distance_mm
          << ',' << b.tangential_px << ',' << b.sagittal_px << ',' << b.tangential_deg << ',' << b.sagittal_deg << ','
          << b.area_deg2 << ',' << f.caustic_x_mm << ',' << f.caustic_z_mm << '\n';
    }
  });
}

void WriteCharacterizeSummaryJson(const CharacterizeResult& r, const std::string& sensor_file,
                                  const std::string& path) {
  nlohmann::json summary;
  summary["sensor"] = sensor_file;
  summary["profile"] = r.profile_name;
  summary["lens"] = r.lens_name;
  summary["analysed_as"] = r.axial ? "axial"
                                   : "aligned counterpart (tilt and decenter set to 0); "
                                     "fig05 adds the exact curves per azimuth";
  summary["samples"] = r.samples;
  summary["rim_omega_deg"] = r.rim_omega_deg();
  summary["rim_theta_deg"] = r.rim_theta_deg();
  summary["rim_h_px"] = r.field.back().h_px;
  summary["viewpoint_spread_mm"] = r.viewpoint_spread_mm();
  summary["viewpoint_range_mm"] = {r.viewpoint_min_mm, r.viewpoint_max_mm};
  summary["caustic_extent_mm"] = {{"radial", r.caustic_radial_mm}, {"axial", r.caustic_axial_mm}};
  summary["max_astigmatism_mm"] = r.max_astigmatism_mm;
  summary["dh_domega_px_per_deg"] = {
      {"min", r.dh_domega_min}, {"max", r.dh_domega_max}, {"at_rim", r.field.back().delta_h_px}};
  summary["lens_focal_mm"] = r.lens.lens_focal_mm;
  summary["f_number"] = r.lens.f_number;
  summary["pixel_um"] = r.pixel_um;
  summary["near_distance_mm"] = r.near_distance_mm;
  summary["best_L0_mm"] = r.focus_mm;
  summary["L0_searched"] = r.focus_searched;
  summary["depth_of_field_mm"] =
      std::isfinite(r.depth_of_field_mm) ? nlohmann::json(r.depth_of_field_mm) : nlohmann::json(nullptr);
  summary["mean_blur_area_deg2"] = r.mean_blur_area_deg2;
  summary["worst_blur_px"] = r.worst_blur_px;
  summary["mean_solid_angle_per_pixel_deg2"] = r.mean_solid_angle_per_pixel_deg2;
  WriteJson(summary, path);
}

}  // namespace omnical
