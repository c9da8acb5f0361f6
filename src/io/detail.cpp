#include "detail.hpp"

#include <fmt/format.h>


namespace swirl::io::detail {
namespace {

bool is_space(char c) { return c == ' ' || c == '\t' || c == '\n' || c == '\r'; }

bool is_name_char(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == ':' ||
         c == '-' || c == '.';
}

// Only what xml_escape produces, plus the other predefined entities: anything
// else in our own files means the file is not ours.
std::string xml_unescape(std::string_view raw) {
  std::string out;
  out.reserve(raw.size());
  for (std::size_t i = 0; i < raw.size(); ++i) {
    if (raw[i] == '<') throw Malformed("'<' inside an attribute value");
    if (raw[i] != '&') {
      out += raw[i];
      continue;
    }
    std::size_t semi = raw.find(';', i);
    if (semi == std::string_view::npos) throw Malformed("unterminated entity in an attribute value");
    std::string_view ent = raw.substr(i + 1, semi - i - 1);
    if (ent == "amp") out += '&';
    else if (ent == "lt") out += '<';
    else if (ent == "gt") out += '>';
    else if (ent == "quot") out += '"';
    else if (ent == "apos") out += '\'';
    else if (ent.size() >= 2 && ent[0] == '#') {
      bool hex = ent[1] == 'x';
      std::string_view digits = ent.substr(hex ? 2 : 1);
      unsigned code = 0;
      auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), code, hex ? 16 : 10);
      if (digits.empty() || ec != std::errc{} || end != digits.data() + digits.size() || code == 0 || code > 127)
        throw Malformed("unsupported character reference &" + std::string(ent) + ";");
      out += static_cast<char>(code);
    } else {
      throw Malformed("unknown entity &" + std::string(ent.substr(0, 20)) + ";");
    }
    i = semi;
  }
  return out;
}

}  // namespace

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default:
        // Parsers turn raw control characters in attributes into spaces.
        if (static_cast<unsigned char>(c) < 0x20) out += fmt::format("&#{};", static_cast<int>(c));
        else out += c;
    }
  }
  return out;
}

const std::string* XmlTag::find(std::string_view key) const {
  for (const auto& [k, v] : attributes)
    if (k == key) return &v;
  return nullptr;
}

const std::string& XmlTag::get(std::string_view key) const {
  if (const std::string* v = find(key)) return *v;
  throw Malformed("<" + name + "> lacks the attribute " + std::string(key));
}

std::optional<XmlTag> XmlScanner::next() {
  const std::size_t n = text_.size();
  for (;;) {
    std::size_t lt = text_.find('<', pos_);
    if (lt == std::string_view::npos) {
      pos_ = n;
      return std::nullopt;
    }
    std::string_view rest = text_.substr(lt);
    if (rest.starts_with("<?") || rest.starts_with("<!--")) {
      bool decl = rest[1] == '?';
      std::size_t end = decl ? text_.find("?>", lt + 2) : text_.find("-->", lt + 4);
      if (end == std::string_view::npos) throw Malformed(decl ? "unterminated <?...?>" : "unterminated comment");
      pos_ = end + (decl ? 2 : 3);
      continue;
    }
    if (rest.starts_with("<!")) throw Malformed("unsupported markup <!...>");

    XmlTag tag;
    std::size_t i = lt + 1;
    if (i < n && text_[i] == '/') {
      tag.closing = true;
      ++i;
    }
    std::size_t start = i;
    while (i < n && is_name_char(text_[i])) ++i;
    if (i == start) throw Malformed("a tag without a name");
    tag.name = std::string(text_.substr(start, i - start));

    for (;;) {
      while (i < n && is_space(text_[i])) ++i;
      if (i >= n) throw Malformed("unterminated tag <" + tag.name + ">");
      if (text_[i] == '>') {
        ++i;
        break;
      }
      if (text_[i] == '/' && !tag.closing) {
        if (i + 1 >= n || text_[i + 1] != '>') throw Malformed("stray '/' in tag <" + tag.name + ">");
        tag.self_closing = true;
        i += 2;
        break;
      }
      if (tag.closing) throw Malformed("attributes in closing tag </" + tag.name + ">");

      start = i;
      while (i < n && is_name_char(text_[i])) ++i;
      if (i == start) throw Malformed("bad attribute syntax in tag <" + tag.name + ">");
      std::string key(text_.substr(start, i - start));
      while (i < n && is_space(text_[i])) ++i;
      if (i >= n || text_[i] != '=') throw Malformed("attribute " + key + " without a value");
      ++i;
      while (i < n && is_space(text_[i])) ++i;
      if (i >= n || (text_[i] != '"' && text_[i] != '\'')) throw Malformed("unquoted value of attribute " + key);
      std::size_t close = text_.find(text_[i], i + 1);
      if (close == std::string_view::npos) throw Malformed("unterminated value of attribute " + key);
      if (tag.find(key)) throw Malformed("duplicate attribute " + key + " in <" + tag.name + ">");
      // Bounds the quadratic duplicate check on hostile input.
      if (tag.attributes.size() >= 64) throw Malformed("too many attributes in <" + tag.name + ">");
      tag.attributes.emplace_back(std::move(key), xml_unescape(text_.substr(i + 1, close - i - 1)));
      i = close + 1;
      if (i < n && !is_space(text_[i]) && text_[i] != '>' && text_[i] != '/')
        throw Malformed("missing space between attributes in <" + tag.name + ">");
    }
    pos_ = i;
    return tag;
  }
}

}  // namespace swirl::io::detail
