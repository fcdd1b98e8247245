#include "oracle/mtl_oracle.hpp"

#include <tiny_obj_loader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>
#include <sstream>
#include <vector>

#include "base/errors.hpp"
#include "importers/mtl_parser.hpp"

namespace tracer::oracle {
namespace {

std::vector<std::string> words(const std::string& line) {
  std::vector<std::string> out;
  std::string word;
  for (char c : line) {
    if (c == ' ' || c == '\t') {
      if (!word.empty()) out.push_back(word), word.clear();
    } else {
      word += c;
    }
  }
  if (!word.empty()) out.push_back(word);
  return out;
}

// A sign, then a digit or a point and a digit: where both readers see a number begin.
bool begins_number(const std::string& w) {
  size_t i = (!w.empty() && (w[0] == '+' || w[0] == '-')) ? 1 : 0;
  if (i < w.size() && w[i] == '.') ++i;
  return i < w.size() && w[i] >= '0' && w[i] <= '9';
}

bool is_colour(const std::string& k) {
  return k == "Ka" || k == "Kd" || k == "Ks" || k == "Ke" || k == "Tf" || k == "Kt";
}

bool is_map(const std::string& k) {
  return k == "map_Kd" || k == "map_bump" || k == "map_Bump" || k == "bump" || k == "map_Ks" || k == "map_Ns" ||
         k == "map_Ke" || k == "norm";
}

// A texture statement with every option's values written out: `-o`, `-s`, `-t` take one to three
// numbers and `-mm` one or two (tinyobjloader always takes three and two, the file name among
// them if fewer are given); options tinyobjloader does not know (`-cc`) are left out.
std::string texture_as_the_format_means(const std::string& original, const std::vector<std::string>& w) {
  std::string line = w[0];
  size_t i = 1;
  while (i + 1 < w.size() && w[i].size() > 1 && w[i][0] == '-' && std::isalpha(static_cast<unsigned char>(w[i][1]))) {
    const std::string option = w[i++];
    static const char* kKnown[] = {"-o",     "-s",       "-t",    "-mm",     "-bm",    "-blendu",    "-blendv",
                                   "-clamp", "-imfchan", "-type", "-texres", "-boost", "-colorspace"};
    if (std::find(std::begin(kKnown), std::end(kKnown), option) == std::end(kKnown)) {
      if (option == "-cc" || i + 1 < w.size()) ++i;  // tracer skips its one value, if a file name follows
      continue;
    }
    const bool counted = option == "-o" || option == "-s" || option == "-t" || option == "-mm";
    std::vector<std::string> values{w[i++]};
    const size_t most = option == "-mm" ? 2 : 3;
    while (counted && values.size() < most && i + 1 < w.size() && begins_number(w[i])) values.push_back(w[i++]);
    while (counted && values.size() < most) values.push_back("1");
    line += " " + option;
    for (const std::string& v : values) line += " " + v;
  }
  // The file name as written, blanks inside it kept.
  size_t at = 0;
  for (size_t k = 0; k < i; ++k) at = original.find(w[k], at) + w[k].size();
  std::string file = original.substr(at);
  file.erase(0, file.find_first_not_of(" \t"));
  return file.empty() ? line : line + " " + file;
}

bool near(float a, float b) { return a == b || std::fabs(a - b) <= 1e-6f * std::fmax(std::fabs(a), std::fabs(b)); }

}  // namespace

namespace {

struct Rewritten {
  std::string text;
  std::set<std::pair<int, std::string>> xyz;  // (material, colour) given as CIE XYZ: not compared
};

Rewritten rewrite(const std::string& text) {
  std::vector<std::string> lines;
  std::string line;
  for (size_t i = 0; i <= text.size(); ++i) {
    if (i == text.size() || text[i] == '\n' || text[i] == '\r') {
      lines.push_back(line);
      line.clear();
      if (i + 1 < text.size() && text[i] == '\r' && text[i + 1] == '\n') ++i;
    } else {
      line += text[i];
    }
  }
  Rewritten r;
  std::string& out = r.text;
  bool has_kd = false;
  int material = -1;
  for (std::string l : lines) {
    l = l.substr(0, std::min(l.find('#'), l.find('\0')));
    const std::vector<std::string> w = words(l);
    if (!w.empty() && w[0] == "newmtl" && w.size() > 1) {
      l = "newmtl " + w[1];
      has_kd = false;
      ++material;
    } else if (!w.empty() && is_colour(w[0]) && w.size() > 1 && w[1] == "xyz") {
      r.xyz.insert({material, w[0] == "Kt" ? "Tf" : w[0]});
    } else if (!w.empty() && is_colour(w[0]) && w.size() > 1 && begins_number(w[1]) &&
               (w.size() == 2 || !begins_number(w[2]))) {
      l = w[0] + " " + w[1] + " " + w[1] + " " + w[1];
    }
    if (!w.empty() && is_map(w[0]) && w.size() > 1) l = texture_as_the_format_means(l, w);
    if (!w.empty() && w[0] == "Kd") has_kd = true;
    if (!w.empty() && w[0] == "map_Kd" && !has_kd) out += "Kd 0.6 0.6 0.6\n";
    out += l + "\n";
  }
  return r;
}

}  // namespace

std::string mtl_as_the_format_means(const std::string& text) { return rewrite(text).text; }

std::optional<std::string> mtl_disagreement(const std::string& text, bool* refused) {
  if (refused) *refused = false;
  MtlFile mine;
  try {
    mine = parse_mtl(text, "t.mtl");
  } catch (const InputError& e) {
    if (refused) *refused = true;
    const std::string what = e.what();
    static const char* kImageBreaking[] = {
        "needs a number",      "malformed number",           "is not a finite number",
        "out of range",        "needs one value or three",   "needs a file name",
        "leaves no file name", "spectral' is not supported", "'newmtl' needs a name"};
    for (const char* reason : kImageBreaking) {
      if (what.find(reason) != std::string::npos) return std::nullopt;
    }
    return "tracer refuses it: " + what;
  }
  std::map<std::string, int> by_name;
  std::vector<tinyobj::material_t> ref;
  std::string warn, err;
  const Rewritten rewritten = rewrite(text);
  std::istringstream in(rewritten.text);
  tinyobj::LoadMtl(&by_name, &ref, &in, &warn, &err);
  if (mine.materials.empty()) return std::nullopt;  // tinyobjloader's one unnamed default
  if (ref.size() != mine.materials.size()) {
    return "materials: tracer " + std::to_string(mine.materials.size()) + ", tinyobjloader " +
           std::to_string(ref.size());
  }
  for (size_t i = 0; i < ref.size(); ++i) {
    const MtlMaterial& a = mine.materials[i];
    const tinyobj::material_t& b = ref[i];
    const std::string at = "material " + std::to_string(i) + " ('" + a.name + "'): ";
    if (a.name != b.name) return at + "name, tinyobjloader '" + b.name + "'";
    const std::pair<const char*, std::pair<Vec3, const float*>> colours[] = {{"Ka", {a.ka, b.ambient}},
                                                                             {"Kd", {a.kd, b.diffuse}},
                                                                             {"Ks", {a.ks, b.specular}},
                                                                             {"Ke", {a.ke, b.emission}},
                                                                             {"Tf", {a.tf, b.transmittance}}};
    for (const auto& [key, pair] : colours) {
      if (rewritten.xyz.count({int(i), key})) continue;
      for (int c = 0; c < 3; ++c) {
        if (!near(pair.first[c], pair.second[c])) {
          return at + key + "[" + std::to_string(c) + "] tracer " + std::to_string(pair.first[c]) + ", tinyobjloader " +
                 std::to_string(pair.second[c]);
        }
      }
    }
    const std::pair<const char*, std::pair<float, float>> scalars[] = {
        {"Ns", {a.ns, b.shininess}},
        {"Ni", {a.ni, b.ior}},
        {"d", {a.dissolve, b.dissolve}},
        {"illum", {float(a.illum), float(b.illum)}},
        {"-bm", {a.bump_multiplier, b.bump_texopt.bump_multiplier}}};
    for (const auto& [key, pair] : scalars) {
      if (!near(pair.first, pair.second)) {
        return at + key + " tracer " + std::to_string(pair.first) + ", tinyobjloader " + std::to_string(pair.second);
      }
    }
    if (a.diffuse_map != b.diffuse_texname)
      return at + "map_Kd '" + a.diffuse_map + "', tinyobjloader '" + b.diffuse_texname + "'";
    const std::pair<const char*, std::pair<const std::string*, const std::string*>> maps[] = {
        {"map_bump", {&a.bump_map, &b.bump_texname}},
        {"map_Ks", {&a.specular_map, &b.specular_texname}},
        {"map_Ns", {&a.shininess_map, &b.specular_highlight_texname}},
        {"map_Ke", {&a.emissive_map, &b.emissive_texname}},
        {"norm", {&a.normal_map, &b.normal_texname}}};
    for (const auto& [key, pair] : maps) {
      if (*pair.first != *pair.second) return at + key + " '" + *pair.first + "', tinyobjloader '" + *pair.second + "'";
    }
  }
  return std::nullopt;
}

}  // namespace tracer::oracle
