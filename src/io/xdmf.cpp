#include "swirl/io/xdmf.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "detail.hpp"
#include "swirl/io/atomic_file.hpp"

namespace swirl::io {
namespace {

// The Gadget datasets first, as the writer orders them, then the rest by
// name: the same description whether the layout came from the writer or was
// read back from a file on resume.
std::vector<SnapshotLayout::Dataset> ordered(std::vector<SnapshotLayout::Dataset> sets) {
  const auto rank = [](const std::string& n) {
    int k = 0;
    for (const char* first : {"Coordinates", "Velocities", "Masses", "ParticleIDs"}) {
      if (n == first) return k;
      ++k;
    }
    return k;
  };
  std::sort(sets.begin(), sets.end(), [&](const auto& a, const auto& b) {
    return rank(a.name) != rank(b.name) ? rank(a.name) < rank(b.name) : a.name < b.name;
  });
  return sets;
}

std::string data_item(const XdmfEntry& e, const SnapshotLayout::Dataset& d) {
  const std::string dims = d.components == 1 ? fmt::format("{}", e.layout.count)
                                             : fmt::format("{} {}", e.layout.count, d.components);
  return fmt::format(R"(<DataItem Dimensions="{}" NumberType="{}" Precision="{}" Format="HDF">{}:/PartType{}/{}</DataItem>)",
                     dims, d.is_unsigned ? "UInt" : d.integer ? "Int" : "Float", d.bytes, detail::xml_escape(e.file), int(e.layout.type),
                     detail::xml_escape(d.name));
}

}  // namespace

std::string xdmf_text(const std::vector<XdmfEntry>& entries, std::string_view series) {
  std::string x;
  x += "<?xml version=\"1.0\" ?>\n<!DOCTYPE Xdmf SYSTEM \"Xdmf.dtd\" []>\n<Xdmf Version=\"2.0\">\n <Domain>\n";
  x += fmt::format("  <Grid Name=\"{}\" GridType=\"Collection\" CollectionType=\"Temporal\">\n",
                   detail::xml_escape(series));
  for (std::size_t f = 0; f < entries.size(); ++f) {
    const XdmfEntry& e = entries[f];
    x += fmt::format("   <Grid Name=\"frame_{}\" GridType=\"Uniform\">\n", f);
    x += fmt::format("    <Time Value=\"{:.17g}\"/>\n", e.layout.time);
    x += fmt::format("    <Topology TopologyType=\"Polyvertex\" NumberOfElements=\"{}\" NodesPerElement=\"1\"/>\n",
                     e.layout.count);
    for (const auto& d : ordered(e.layout.datasets)) {
      if (d.name == "Coordinates") {
        x += "    <Geometry GeometryType=\"XYZ\">\n     " + data_item(e, d) + "\n    </Geometry>\n";
      } else if (d.components == 1 || d.components == 3) {
        x += fmt::format("    <Attribute Name=\"{}\" AttributeType=\"{}\" Center=\"Node\">\n     {}\n    </Attribute>\n",
                         detail::xml_escape(d.name), d.components == 1 ? "Scalar" : "Vector", data_item(e, d));
      }
    }
    x += "   </Grid>\n";
  }
  x += "  </Grid>\n </Domain>\n</Xdmf>\n";
  return x;
}

void XdmfSeries::add(const std::string& relative_file, SnapshotLayout layout) {
  entries_.push_back({relative_file, std::move(layout)});
  write_file_atomic(path_, xdmf_text(entries_, path_.stem().string()));
}

}  // namespace swirl::io
