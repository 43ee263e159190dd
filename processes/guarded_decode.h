#pragma once
// The one way every process decodes a raw LCM message. The generated
// decoders are hardened at build time (lcmtypes/harden_decoders.cmake: every
// string length and array count is bounded by the bytes left before anything
// is allocated); this adds the reason a message does not decode, and turns
// anything a decoder might still throw into such a reason.
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <exception>
#include <limits>
#include <string>

namespace acyclic::proc {

// Decodes `size` bytes as Msg into `out`. Returns "" when they decode as
// exactly one Msg, else why not.
template <class Msg>
std::string whyNotDecoded(const void* data, std::size_t size, Msg& out) {
  const auto* b = static_cast<const unsigned char*>(data);
  if (size < 8) return "shorter than a type fingerprint (" + std::to_string(size) + " bytes)";
  if (size > static_cast<std::size_t>(std::numeric_limits<int>::max())) return "larger than LCM allows";
  std::uint64_t hash = 0;
  for (int i = 0; i < 8; ++i) hash = (hash << 8) | b[i];
  if (hash != static_cast<std::uint64_t>(Msg::getHash())) {
    char why[120];
    std::snprintf(why, sizeof why, "type fingerprint %016llx is not %s's (%016llx)",
                  static_cast<unsigned long long>(hash), Msg::getTypeName(),
                  static_cast<unsigned long long>(Msg::getHash()));
    return why;
  }
  int used = -1;
  try {
    used = out.decode(data, 0, static_cast<int>(size));
  } catch (const std::exception& e) {
    return std::string("the decoder failed: ") + e.what();
  }
  if (used < 0) return "a string length or array count out of bounds, or the message is cut short";
  if (static_cast<std::size_t>(used) != size)
    return std::to_string(size - static_cast<std::size_t>(used)) + " bytes after the message's end";
  return {};
}

}  // namespace acyclic::proc
