// The library's result structs as JSON and as summary rows, generated from their field tables
// (for_each_stats_field, for_each_report_field) so that a new field shows up without a change here.
#pragma once

#include <nlohmann/json.hpp>

#include <string>
#include <string_view>

#include "exactgeo/exactgeo.hpp"
#include "outputs.hpp"

namespace exactgeo::cli {

// Phase times that were not measured (`timed` false) are null, not a misleading zero.
inline nlohmann::ordered_json stats_json(const exactgeo::GeodesicStats& stats, bool timed) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  exactgeo::for_each_stats_field([&](const char* name, auto member, exactgeo::StatsFieldKind kind, const char*) {
    json[name] = kind == exactgeo::StatsFieldKind::phase_seconds && !timed ? nlohmann::ordered_json()
                                                                          : nlohmann::ordered_json(stats.*member);
  });
  if (!stats.band_timeline.empty()) {  // as columns: one array per field, one entry per band
    nlohmann::ordered_json bands = nlohmann::ordered_json::object();
    auto column = [&](const char* name, auto member) {
      nlohmann::ordered_json values = nlohmann::ordered_json::array();
      for (const exactgeo::GeodesicStats::Band& band : stats.band_timeline) values.push_back(band.*member);
      bands[name] = std::move(values);
    };
    using Band = exactgeo::GeodesicStats::Band;
    column("vertices", &Band::vertices);
    column("crossings", &Band::crossings);
    column("depth", &Band::depth);
    column("seconds", &Band::seconds);
    column("busy_seconds", &Band::busy_seconds);
    json["band_timeline"] = std::move(bands);
  }
  return json;
}

inline nlohmann::ordered_json report_json(const exactgeo::MeshReport& report) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  exactgeo::for_each_report_field([&](const char* name, auto member, const char*) { json[name] = report.*member; });
  return json;
}

// The build's steps (for_each_build_stats_field), seconds each; the total and the thread count are
// reported beside them as build_seconds and build_threads.
inline nlohmann::ordered_json build_timings_json(const exactgeo::MeshBuildStats& stats) {
  nlohmann::ordered_json json = nlohmann::ordered_json::object();
  exactgeo::for_each_build_stats_field([&](std::string_view name, auto member, const char*) {
    if (name.ends_with("_seconds")) json[std::string(name)] = stats.*member;
  });
  return json;
}

inline Rows report_rows(const exactgeo::MeshReport& report) {
  Rows rows;
  exactgeo::for_each_report_field(
      [&](const char* name, auto member, const char*) { rows.emplace_back(name, std::to_string(report.*member)); });
  return rows;
}

}  // namespace exactgeo::cli
