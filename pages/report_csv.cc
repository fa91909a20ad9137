#include "pages/report_csv.h"

#include <sstream>

#include "pages/report_json.h"
#include "pages/report_text.h"

namespace fitcal::io {

using namespace report_text;

std::string MetricsCsv(const ReportData& d) {
  std::ostringstream c;
  c << "run,trajectory,repetition";
  for (const char* when : {"before", "after"}) {
    for (const Column& col : kColumns) c << "," << when << "_" << KeyOf(col);
  }
  // Signed final errors in the start frame (the bias of the summary) and the path length.
  c << ",path_length_m,before_final_x_m,before_final_y_m,before_final_heading_deg,"
       "after_final_x_m,after_final_y_m,after_final_heading_deg\n";
  for (const ReportRun& r : d.runs) {
    c << r.id << "," << r.trajectory << "," << r.repetition;
    for (const ReportMetrics* m : {&r.before, &r.after}) {
      for (const Column& col : kColumns) c << "," << JsonNumber(ValueOf(col, *m));
    }
    c << "," << JsonNumber(r.path_length_m);
    for (bool after : {false, true}) {
      const Point2& e = after ? r.after_final_error : r.before_final_error;
      c << "," << JsonNumber(e.x) << "," << JsonNumber(e.y) << ","
        << JsonNumber(kDeg * (after ? r.after_final_heading_rad : r.before_final_heading_rad));
    }
    c << "\n";
  }
  return c.str();
}

}  // namespace fitcal::io
