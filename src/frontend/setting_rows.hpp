// The makers of the settings table's rows (settings_table.cpp), one per kind of value: whole
// numbers, reals, names of an enum, x,y,z vectors, file names, toggles and lists. Each gives a
// row its text, range check, copy, command-line parse and viewer JSON from the field it binds.
#pragma once

#include <nlohmann/json.hpp>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <optional>
#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include "base/errors.hpp"
#include "base/whole_number.hpp"
#include "frontend/parse.hpp"
#include "frontend/settings_table.hpp"
#include "scene/value_limits.hpp"

namespace tracer::frontend::setting_rows {

using json = nlohmann::json;

template <class T>
struct Unwrap {
  using type = T;
  static constexpr bool optional = false;
};
template <class T>
struct Unwrap<std::optional<T>> {
  using type = T;
  static constexpr bool optional = true;
};

// A row's field: the member of RenderArgs it reads and writes.
template <class T>
using Field = T& (*)(RenderArgs&);
template <class T>
const T& get(Field<T> field, const RenderArgs& a) {
  return field(const_cast<RenderArgs&>(a));
}

// What a value type needs for a row: its text, its range, its JSON.
template <class V>
struct Codec {
  std::string value_name;  // for --help
  std::function<V(const std::string& name, const std::string& text)> parse;
  std::function<std::string(const V&)> format;
  std::function<void(const std::string& name, const V&)> check;  // null: every value parse gives is in range
  std::function<V(const std::string& name, const json&)> from_json;
};

// The shortest text that reads back as the same value of its type.
template <class F>
std::string shortest(F v) {
  char text[32];
  const auto end = std::to_chars(text, text + sizeof text, v).ptr;
  return std::string(text, end);
}

inline double json_number(const std::string& name, const json& value) {
  if (!value.is_number()) throw UsageError(name + ": expected a number, got " + value.dump());
  return value.get<double>();
}

// The command line's numbers are whole words (base/whole_number.hpp); the viewer's JSON numbers
// are nlohmann-json's.
template <class I>
Codec<I> whole(long long lo, long long hi) {
  Codec<I> c;
  c.value_name = "INT";
  c.parse = [lo, hi](const std::string& name, const std::string& text) {
    long long v = 0;
    const WholeNumber read = read_whole_number(text, v);
    if (read == WholeNumber::NotANumber) throw UsageError(name + ": expected a whole number, got '" + text + "'");
    // Checked on the text as given: a number beyond long long is quoted as typed.
    if (read == WholeNumber::OutOfRange || v < lo || v > hi)
      throw UsageError(name + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " +
                       text);
    return I(v);
  };
  c.format = [](const I& v) { return std::to_string(v); };
  c.check = [lo, hi](const std::string& name, const I& v) { check_range(name, (long long)v, lo, hi); };
  c.from_json = [lo, hi](const std::string& name, const json& value) {
    const double v = json_number(name, value);
    if (v != std::floor(v)) throw UsageError(name + ": expected a whole number, got " + value.dump());
    if (!(v >= double(lo) && v <= double(hi)))
      throw UsageError(name + ": must be between " + std::to_string(lo) + " and " + std::to_string(hi) + ", got " +
                       value.dump());
    return I(v);
  };
  return c;
}

template <class F>
Codec<F> real(double lo, double hi, LowEnd low = LowEnd::Closed) {
  Codec<F> c;
  c.value_name = "FLOAT";
  c.parse = [](const std::string& name, const std::string& text) {
    double v = 0;
    const WholeNumber read = read_whole_number(text, v);
    if (read == WholeNumber::NotANumber) throw UsageError(name + ": expected a number, got '" + text + "'");
    if (read == WholeNumber::OutOfRange)
      throw UsageError(name + ": '" + text + "' is out of range (not a finite number)");
    return F(v);
  };
  c.format = [](const F& v) { return shortest(v); };
  c.check = [lo, hi, low](const std::string& name, const F& v) { check_range_real(name, double(v), lo, hi, low); };
  c.from_json = [](const std::string& name, const json& value) { return F(json_number(name, value)); };
  return c;
}

template <class E>
Codec<E> choice(std::span<const EnumName<E>> names, std::string what) {
  Codec<E> c;
  c.value_name = "NAME";
  c.parse = [names, what](const std::string& name, const std::string& text) {
    return parse_name<E>(names, text, name, what);
  };
  c.format = [names](const E& v) { return std::string(name_of<E>(names, v)); };
  c.from_json = [names, what](const std::string& name, const json& value) {
    if (!value.is_string()) throw UsageError(name + ": expected a name, got " + value.dump());
    return parse_name<E>(names, value.get<std::string>(), name, what);
  };
  return c;
}

// x,y,z: a position (within the coordinates floats hold), a direction (not zero) or a radiance.
enum class VecKind { Point, Direction, Radiance };
inline Codec<Vec3> vector(VecKind kind) {
  Codec<Vec3> c;
  c.value_name = "X,Y,Z";
  c.parse = [](const std::string& name, const std::string& text) { return parse_vec3(name, text); };
  c.format = [](const Vec3& v) { return shortest(v.x) + "," + shortest(v.y) + "," + shortest(v.z); };
  c.check = [kind](const std::string& name, const Vec3& v) {
    const std::string text = shortest(v.x) + "," + shortest(v.y) + "," + shortest(v.z);
    for (const float x : {v.x, v.y, v.z}) {
      if (!std::isfinite(x)) throw UsageError(name + ": '" + text + "' is out of range (not a finite float)");
    }
    switch (kind) {
      case VecKind::Point:
        if (std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)}) > kMaxCoordinate)
          throw UsageError(name + ": coordinates must lie within +-" + kMaxCoordinateText + ", got '" + text + "'");
        break;
      case VecKind::Direction:
        if (length(v) == 0.0f) throw UsageError(name + ": must not be the zero vector");
        break;
      case VecKind::Radiance:
        if (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f || max_component(v) > kMaxEmission)
          throw UsageError(name + ": each component must be in [0, 1e6] (the radiance limit of every format), got '" +
                           text + "'");
        break;
    }
  };
  c.from_json = [](const std::string& name, const json& value) {
    if (!value.is_array() || value.size() != 3) throw UsageError(name + ": expected [x, y, z], got " + value.dump());
    Vec3 v;
    for (int i = 0; i < 3; ++i) {
      const double x = json_number(name, value[size_t(i)]);
      if (!(std::fabs(x) <= 1e12))
        throw UsageError(name + ": " + value[size_t(i)].dump() + " is outside [-1e12, 1e12]");
      v[i] = float(x);
    }
    return v;
  };
  return c;
}

// A name (a file, a view): any text, or with `nonempty` any but the empty one.
inline Codec<std::string> name_codec(bool nonempty) {
  Codec<std::string> c;
  c.value_name = nonempty ? "FILE" : "TEXT";
  c.parse = [nonempty](const std::string& name, const std::string& text) {
    if (nonempty && text.empty()) throw UsageError(name + ": an empty file name");
    return text;
  };
  c.format = [](const std::string& v) { return v; };
  return c;
}

// A row of a single value of type T (V, or an optional V: not given until set).
template <class T, class V = typename Unwrap<T>::type>
Setting row(Setting s, Field<T> field, Codec<V> c) {
  constexpr bool optional = Unwrap<T>::optional;
  const auto value = [field](const RenderArgs& a) -> std::optional<V> {
    if constexpr (optional) {
      return get(field, a);
    } else {
      return get(field, a);
    }
  };
  s.value_name = c.value_name;
  s.text = [value, c](const RenderArgs& a) -> std::optional<std::string> {
    const std::optional<V> v = value(a);
    if (!v) return std::nullopt;
    if constexpr (std::is_same_v<V, std::string>) {
      if (v->empty()) return std::nullopt;
    }
    return c.format(*v);
  };
  s.check = [value, c](const RenderArgs& a, const std::string& name) {
    if (const std::optional<V> v = value(a); v && c.check) c.check(name, *v);
  };
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field, c, flag = s.flag()](RenderArgs& a, const std::string& text) { field(a) = c.parse(flag, text); };
  if (!s.key.empty()) {
    s.read_json = [field, c, key = s.key](RenderArgs& a, const json& v) { field(a) = c.from_json(key, v); };
    s.json = [value, c](const RenderArgs& a) -> json {
      const std::optional<V> v = value(a);
      if (!v) return nullptr;
      if constexpr (std::is_same_v<V, Vec3>) {
        return json::array({v->x, v->y, v->z});
      } else if constexpr (std::is_enum_v<V>) {
        return c.format(*v);
      } else {
        return *v;
      }
    };
  }
  return s;
}

inline Setting toggle(Setting s, Field<bool> field) {
  s.toggle = true;
  s.text = [field](const RenderArgs& a) -> std::optional<std::string> {
    return get(field, a) ? std::optional<std::string>("") : std::nullopt;
  };
  s.check = [](const RenderArgs&, const std::string&) {};
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field](RenderArgs& a, const std::string&) { field(a) = true; };
  return s;
}

// --packets and --no-packets: the two settings of one optional toggle.
inline Setting tristate(Setting s, Field<std::optional<bool>> field, bool on) {
  s.toggle = true;
  s.text = [field, on](const RenderArgs& a) -> std::optional<std::string> {
    return get(field, a) == on ? std::optional<std::string>("") : std::nullopt;
  };
  s.check = [](const RenderArgs&, const std::string&) {};
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field, on](RenderArgs& a, const std::string&) { field(a) = on; };
  return s;
}

// A repeatable flag: each given value appended.
inline Setting points(Setting s, Field<std::vector<Vec3>> field) {
  const Codec<Vec3> c = vector(VecKind::Point);
  s.repeatable = true;
  s.value_name = c.value_name;
  s.text = [field, c](const RenderArgs& a) -> std::optional<std::string> {
    std::string out;
    for (const Vec3& v : get(field, a)) out += (out.empty() ? "" : " ") + c.format(v);
    return out.empty() ? std::nullopt : std::optional<std::string>(out);
  };
  s.check = [field, c](const RenderArgs& a, const std::string& name) {
    for (const Vec3& v : get(field, a)) c.check(name, v);
  };
  s.copy = [field](RenderArgs& a, const RenderArgs& from) { field(a) = get(field, from); };
  s.parse = [field, c, flag = s.flag()](RenderArgs& a, const std::string& text) {
    field(a).push_back(c.parse(flag, text));
  };
  return s;
}

inline constexpr IntegratorSet kPath{Integrator::Path};
inline constexpr IntegratorSet kLit{Integrator::Path, Integrator::Whitted};  // light from beyond the scene
inline constexpr IntegratorSet kAo{Integrator::Ao};

}  // namespace tracer::frontend::setting_rows
