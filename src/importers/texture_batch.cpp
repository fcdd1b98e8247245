#include "importers/texture_batch.hpp"

#include <algorithm>
#include <cstdint>

#include "base/byte_budget.hpp"

namespace tracer {

TextureBatch read_and_decode(size_t count, const std::function<EncodedTexture(size_t)>& read, const LoadLimits& limits,
                             CancelFlag cancel) {
  TextureBatch t;
  std::vector<EncodedTexture> encoded(count);
  t.problem.resize(count);
  t.decoded.resize(count);
  const auto guarded = [&](size_t k, auto&& work) {
    try {
      work();
    } catch (const InputError& e) {
      t.problem[k] = e.what();
    }
  };
  limits.for_each(count, [&](size_t k) { guarded(k, [&] { encoded[k] = read(k); }); });
  throw_if_cancelled(cancel);
  // The budget holds the decoded textures and, beside them, the largest decode's transient
  // buffers: decodes then run at once only while their transients fit what is left (ByteBudget),
  // and one always can, so peak memory stays within the budget (and the encoded files' bytes).
  const uint64_t budget = limits.textures.max_total_bytes;
  uint64_t kept = 0, largest_transient = 0;
  for (size_t k = 0; k < count; ++k) {
    if (!t.problem[k].empty()) continue;
    const uint64_t final_bytes = encoded[k].decoded_bytes();
    const uint64_t transient = encoded[k].decode_peak_bytes() - final_bytes;
    if (kept + final_bytes + std::max(largest_transient, transient) > budget) {
      t.problem[k] = "the scene's textures would take more than " + std::to_string(budget >> 20) +
                     " MiB to decode (--max-texture-mib raises it)";
      encoded[k] = {};
      continue;
    }
    kept += final_bytes;
    largest_transient = std::max(largest_transient, transient);
  }
  ByteBudget transients(budget - kept);
  limits.for_each(count, [&](size_t k) {
    if (t.problem[k].empty()) {
      const uint64_t transient = encoded[k].decode_peak_bytes() - encoded[k].decoded_bytes();
      const ByteBudget::Taken held(transients, transient);
      guarded(k, [&] { t.decoded[k] = decode_texture(encoded[k]); });
    }
    encoded[k] = {};  // the encoded bytes are no longer needed
  });
  throw_if_cancelled(cancel);
  return t;
}

}  // namespace tracer
