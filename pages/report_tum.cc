#include "pages/report_tum.h"

#include "io/tum_file.h"

namespace fitcal::io {

std::vector<ReportFile> ReportTumFiles(const ReportData& data) {
  std::vector<ReportFile> files;
  for (const ReportWorldTrack& track : data.world_tracks) {
    const std::string stem = "tum/" + FileNameOf(track.run_id);
    files.push_back({stem + ".ground_truth.tum", TumText(track.t_s, track.ground_truth)});
    files.push_back({stem + ".nominal.tum", TumText(track.t_s, track.nominal)});
    files.push_back({stem + ".calibrated.tum", TumText(track.t_s, track.calibrated)});
  }
  return files;
}

}  // namespace fitcal::io
