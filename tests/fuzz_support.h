#pragma once
// Malformed variants of a good LCM message for the process-level fuzz tests:
// truncations, 4-byte windows set to the length or count values that killed
// processes (0, -1, 2^27, INT_MAX), a wrong fingerprint, bit flips and random
// bytes behind the right fingerprint. Seeded: the same list every run.
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

namespace acyclic::test {

using Bytes = std::vector<unsigned char>;

template <class Msg>
Bytes encoded(const Msg& m) {
  Bytes b(m.getEncodedSize());
  m.encode(b.data(), 0, static_cast<int>(b.size()));
  return b;
}

// At most about `max` variants of `good` (which should be small: every
// 4-byte window after the fingerprint is tried when room allows).
inline std::vector<Bytes> malformed(const Bytes& good, std::uint64_t seed, std::size_t max = 400) {
  std::vector<Bytes> out;
  std::mt19937_64 rng(seed);
  const std::size_t step_cut = good.size() / 24 + 1;
  for (std::size_t n = 0; n < good.size(); n += step_cut) out.emplace_back(good.begin(), good.begin() + n);
  Bytes wrong = good;
  wrong[0] ^= 0x5A;
  out.push_back(wrong);
  const std::uint32_t values[] = {0u, 0xFFFFFFFFu, 1u << 27, 0x7FFFFFFFu};
  const std::size_t windows = good.size() > 12 ? good.size() - 11 : 0;
  const std::size_t step_win = windows * 4 > max / 2 ? windows * 4 / (max / 2) + 1 : 1;
  for (std::size_t off = 8; off + 4 <= good.size(); off += step_win)
    for (const std::uint32_t v : values) {
      Bytes b = good;
      b[off] = v >> 24, b[off + 1] = (v >> 16) & 0xFF, b[off + 2] = (v >> 8) & 0xFF, b[off + 3] = v & 0xFF;
      out.push_back(b);
    }
  while (out.size() < max) {
    Bytes b = good;
    if (rng() % 2) {
      for (int f = 0; f < 3; ++f) b[8 + rng() % (b.size() - 8)] ^= static_cast<unsigned char>(1u << (rng() % 8));
    } else {
      b.resize(8 + rng() % (2 * good.size()));
      for (std::size_t i = 8; i < b.size(); ++i) b[i] = static_cast<unsigned char>(rng());
    }
    out.push_back(b);
  }
  return out;
}

// Peak and current resident memory of a process, in KiB (/proc/PID/status).
inline long residentKib(int pid, const char* field = "VmHWM:") {
  FILE* f = std::fopen(("/proc/" + std::to_string(pid) + "/status").c_str(), "r");
  if (!f) return -1;
  char line[256];
  long kib = -1;
  const std::size_t len = std::char_traits<char>::length(field);
  while (std::fgets(line, sizeof line, f))
    if (std::string(line).compare(0, len, field) == 0) kib = std::atol(line + len);
  std::fclose(f);
  return kib;
}

}  // namespace acyclic::test
