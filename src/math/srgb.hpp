// The sRGB transfer curve (IEC 61966-2-1), both ways: texels and 8-bit vertex colours are stored
// encoded, light is computed linear, and images are written encoded.
#pragma once

#include <cmath>

namespace tracer {

template <class T>
T srgb_to_linear(T c) {
  return c <= T(0.04045) ? c / T(12.92) : std::pow((c + T(0.055)) / T(1.055), T(2.4));
}

template <class T>
T linear_to_srgb(T c) {
  return c <= T(0.0031308) ? T(12.92) * c : T(1.055) * std::pow(c, T(1) / T(2.4)) - T(0.055);
}

}  // namespace tracer
