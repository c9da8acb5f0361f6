#include "swirl/io/pvd.hpp"

#include <fmt/format.h>

#include "detail.hpp"
#include "swirl/io/atomic_file.hpp"
#include "swirl/io/read_file.hpp"

namespace swirl::io {

namespace fs = std::filesystem;
using detail::Malformed;

PvdSeries::PvdSeries(fs::path pvd_path) : path_(std::move(pvd_path)) {}

void PvdSeries::add(double time, const std::string& relative_file) {
  std::vector<PvdEntry> entries = entries_;
  entries.push_back({time, relative_file});
  std::string xml =
      "<?xml version=\"1.0\"?>\n"
      "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
      "  <Collection>\n";
  // 17 significant digits make every double round-trip exactly.
  for (const PvdEntry& e : entries)
    xml += fmt::format("    <DataSet timestep=\"{:.17g}\" group=\"\" part=\"0\" file=\"{}\"/>\n", e.time,
                       detail::xml_escape(e.file));
  xml += "  </Collection>\n</VTKFile>\n";
  // Entries change only once the file is written, so a failed add() can be retried.
  write_file_atomic(path_, xml);
  entries_ = std::move(entries);
}

std::vector<PvdEntry> read_pvd(const fs::path& path) {
  const std::string text = read_regular_file(path, kMaxSeriesBytes);
  try {
    std::vector<PvdEntry> entries;
    detail::XmlScanner scan(text);
    std::vector<std::string> open;
    bool seen_root = false;
    while (auto tag = scan.next()) {
      if (tag->closing) {
        if (open.empty() || open.back() != tag->name) throw Malformed("unexpected </" + tag->name + ">");
        open.pop_back();
        continue;
      }
      const std::string parent = open.empty() ? "" : open.back();
      if (tag->name == "VTKFile" && parent.empty() && !seen_root) {
        seen_root = true;
        if (tag->get("type") != "Collection") throw Malformed("not a Collection file");
      } else if (tag->name == "DataSet" && parent == "Collection") {
        PvdEntry e;
        e.time = detail::parse_number<double>(tag->get("timestep"), "timestep");
        e.file = tag->get("file");
        if (e.file.empty()) throw Malformed("DataSet with an empty file name");
        entries.push_back(std::move(e));
      } else if (tag->name != "Collection" || parent != "VTKFile") {
        throw Malformed(fmt::format("unexpected element <{}> inside <{}>", tag->name, parent));
      }
      if (!tag->self_closing) open.push_back(tag->name);
    }
    if (!seen_root) throw Malformed("no <VTKFile>");
    if (!open.empty()) throw Malformed("<" + open.back() + "> is not closed");
    return entries;
  } catch (const Malformed& e) {
    throw IoError(fmt::format("{}: {}", path.string(), e.what()));
  }
}

}  // namespace swirl::io
