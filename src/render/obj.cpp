#include "swirl/render/obj.hpp"

#include <charconv>
#include <string_view>
#include <system_error>

#include <fmt/format.h>

#include "swirl/io/atomic_file.hpp"
#include "swirl/io/read_file.hpp"

namespace swirl::render {

std::string encode_obj(const SurfaceMesh& mesh, double time) {
  std::string out = fmt::format(
      "# swirl fluid surface (marching tetrahedra of the colour field)\n# time {:.17g}\n# iso {:.17g}\n"
      "# {} vertices, {} triangles\n",
      time, mesh.iso, mesh.vertices.size(), mesh.triangle_count());
  out.reserve(out.size() + 64 * mesh.vertices.size() + 32 * mesh.triangle_count());
  auto sink = std::back_inserter(out);
  for (const auto& v : mesh.vertices) fmt::format_to(sink, "v {} {} {}\n", v.x, v.y, v.z);
  for (const auto& n : mesh.normals) fmt::format_to(sink, "vn {} {} {}\n", n.x, n.y, n.z);
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const std::uint32_t a = mesh.indices[3 * t] + 1, b = mesh.indices[3 * t + 1] + 1, c = mesh.indices[3 * t + 2] + 1;
    fmt::format_to(sink, "f {}//{} {}//{} {}//{}\n", a, a, b, b, c, c);
  }
  return out;
}

void write_obj(const std::filesystem::path& path, const SurfaceMesh& mesh, double time) {
  io::write_file_atomic(path, encode_obj(mesh, time));
}

namespace {

// The words of a line, split at single spaces (what encode_obj writes).
class Words {
 public:
  explicit Words(std::string_view line) : rest_(line) {}
  bool next(std::string_view& word) {
    if (rest_.empty()) return false;
    const std::size_t space = rest_.find(' ');
    word = rest_.substr(0, space);
    rest_ = space == std::string_view::npos ? std::string_view{} : rest_.substr(space + 1);
    return true;
  }

 private:
  std::string_view rest_;
};

template <class T>
bool parse(std::string_view word, T& value) {
  const auto [end, ec] = std::from_chars(word.data(), word.data() + word.size(), value);
  return ec == std::errc{} && end == word.data() + word.size();
}

}  // namespace

ObjFile read_obj(const std::filesystem::path& path) {
  const std::string text = io::read_regular_file(path, std::uintmax_t{1} << 36);
  ObjFile file;
  std::size_t line_no = 0, normals = 0;
  auto fail = [&](const std::string& why) {
    const std::string where = line_no > 0 ? fmt::format("{}:{}", path.string(), line_no) : path.string();
    return io::IoError(fmt::format("{}: not a swirl surface OBJ file: {}", where, why));
  };
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t end = text.find('\n', at);
    const std::string_view line(text.data() + at, (end == std::string::npos ? text.size() : end) - at);
    at = end == std::string::npos ? text.size() : end + 1;
    ++line_no;
    Words words(line);
    std::string_view kind;
    if (!words.next(kind)) continue;  // an empty line
    if (kind == "#") {
      std::string_view key, value;
      if (words.next(key) && words.next(value)) {
        double x = 0;
        if ((key == "time" || key == "iso") && !parse(value, x)) throw fail(fmt::format("'# {} {}'", key, value));
        if (key == "time") file.time = x;
        if (key == "iso") file.mesh.iso = x;
      }
      continue;
    }
    if (kind == "v" || kind == "vn") {
      Vec3<float> p;
      std::string_view w;
      for (int a = 0; a < 3; ++a)
        if (!words.next(w) || !parse(w, p[a])) throw fail(fmt::format("'{}' needs three numbers", line));
      if (words.next(w)) throw fail(fmt::format("'{}' has more than three numbers", line));
      if (kind == "v") {
        file.mesh.vertices.push_back(p);
      } else {
        if (normals >= file.mesh.vertices.size()) throw fail("a normal before its vertex");
        file.mesh.normals.push_back(p);
        ++normals;
      }
      continue;
    }
    if (kind == "f") {
      std::string_view w;
      for (int c = 0; c < 3; ++c) {
        const std::size_t slashes = words.next(w) ? w.find("//") : std::string_view::npos;
        std::uint64_t v = 0, n = 0;
        if (slashes == std::string_view::npos || !parse(w.substr(0, slashes), v) || !parse(w.substr(slashes + 2), n))
          throw fail(fmt::format("'{}': a face is three v//vn pairs", line));
        if (v != n) throw fail(fmt::format("'{}': vertex {} with normal {}", line, v, n));
        if (v < 1 || v > file.mesh.vertices.size())
          throw fail(fmt::format("'{}' names vertex {} of {}", line, v, file.mesh.vertices.size()));
        file.mesh.indices.push_back(static_cast<std::uint32_t>(v - 1));
      }
      if (words.next(w)) throw fail(fmt::format("'{}' is not a triangle", line));
      continue;
    }
    throw fail(fmt::format("unexpected record '{}'", kind));
  }
  line_no = 0;  // the whole file's
  if (file.mesh.normals.size() != file.mesh.vertices.size())
    throw fail(fmt::format("{} normals for {} vertices", file.mesh.normals.size(), file.mesh.vertices.size()));
  return file;
}

}  // namespace swirl::render
