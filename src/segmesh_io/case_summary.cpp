#include "segmesh_io/case_summary.hpp"

#include <cstdio>

#include "segmesh_io/atomic_file.hpp"

namespace segmesh {

namespace {

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string out = "\"";
  for (const char c : text) out += c == '"' ? std::string("\"\"") : std::string(1, c);
  return out + "\"";
}

std::string number(const char* format, double value) {
  char text[64];
  std::snprintf(text, sizeof text, format, value);
  return text;
}

}  // namespace

void write_case_summary(const std::filesystem::path& file, const std::vector<CaseResult>& rows) {
  AtomicFile out(file);
  std::ostream& s = out.stream();
  s << "case,input,status,parts,triangles,volume_mm3,seconds,error\n";
  for (const CaseResult& r : rows) {
    const bool numbers = r.status == CaseStatus::ok || r.status == CaseStatus::skipped;
    s << csv_field(r.name) << ',' << csv_field(r.input) << ',' << case_status_name(r.status) << ','
      << (numbers ? std::to_string(r.parts) : "") << ','
      << (numbers ? std::to_string(r.triangles) : "") << ','
      << (numbers ? number("%.3f", r.volume_mm3) : "") << ','
      << (r.status == CaseStatus::pending ? "" : number("%.3f", r.seconds)) << ','
      << csv_field(r.error) << '\n';
  }
  out.commit();
}

std::string summary_file_name(int shard, int shard_count) {
  if (shard_count <= 1) return "summary.csv";
  return "summary-" + std::to_string(shard) + "-of-" + std::to_string(shard_count) + ".csv";
}

}  // namespace segmesh
