// The command line's compress, compress2 and uncompress (cli/libdeflate_zlib.cpp, made by
// libdeflate) against zlib's own functions, reached past them with dlsym(RTLD_NEXT): whatever one
// writes the other reads back to the byte, and where zlib fails the stand-ins fail the same way (zlib
// 1.2.13's manual: Z_BUF_ERROR when the output does not fit, Z_DATA_ERROR for a damaged stream).
#include <dlfcn.h>
#include <zlib.h>

#include <catch2/catch.hpp>
#include <cstdint>
#include <cstring>
#include <random>
#include <vector>

namespace {

using Compress2 = int (*)(Bytef*, uLongf*, const Bytef*, uLong, int);
using Uncompress = int (*)(Bytef*, uLongf*, const Bytef*, uLong);

Compress2 zlib_compress2() { return reinterpret_cast<Compress2>(dlsym(RTLD_NEXT, "compress2")); }
Uncompress zlib_uncompress() { return reinterpret_cast<Uncompress>(dlsym(RTLD_NEXT, "uncompress")); }

// What an EXR's ZIP block holds after OpenEXR's predictor: float pixels of a smooth gradient with
// noisy low mantissa bits (the part that hardly compresses), 16 rows of 600 RGB floats.
std::vector<Bytef> exr_like_block() {
  std::mt19937 random(12);
  std::uniform_real_distribution<float> noise(-1e-3f, 1e-3f);
  std::vector<float> pixels(16 * 600 * 3);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = 0.25f + 1e-4f * static_cast<float>(i % 1800) + noise(random);
  std::vector<Bytef> bytes(pixels.size() * sizeof(float));
  std::memcpy(bytes.data(), pixels.data(), bytes.size());
  return bytes;
}

std::vector<Bytef> random_bytes(std::size_t n) {
  std::mt19937 random(7);
  std::vector<Bytef> bytes(n);
  for (Bytef& b : bytes) b = static_cast<Bytef>(random() & 0xffu);
  return bytes;
}

// Compressed by `compress`, read back by `uncompress`; the bytes must come back as they were.
template <class CompressFn, class UncompressFn>
void check_round_trip(const std::vector<Bytef>& data, int level, CompressFn compress_fn, UncompressFn uncompress_fn) {
  std::vector<Bytef> packed(compressBound(static_cast<uLong>(data.size())));
  uLongf packed_size = static_cast<uLongf>(packed.size());
  REQUIRE(compress_fn(packed.data(), &packed_size, data.data(), static_cast<uLong>(data.size()), level) == Z_OK);
  std::vector<Bytef> back(data.size());
  uLongf back_size = static_cast<uLongf>(back.size());
  REQUIRE(uncompress_fn(back.data(), &back_size, packed.data(), packed_size) == Z_OK);
  CHECK(back_size == data.size());
  CHECK(back == data);
}

}  // namespace

TEST_CASE("zlib itself is reachable past the stand-ins, so that the comparisons below compare two codecs") {
  REQUIRE(zlib_compress2() != nullptr);
  REQUIRE(zlib_uncompress() != nullptr);
  CHECK(reinterpret_cast<void*>(zlib_compress2()) != reinterpret_cast<void*>(&compress2));
  CHECK(reinterpret_cast<void*>(zlib_uncompress()) != reinterpret_cast<void*>(&uncompress));
}

TEST_CASE("what the stand-in compress2 writes, zlib reads back to the byte, at every zlib level") {
  const std::vector<Bytef> block = exr_like_block();
  for (int level : {-1, 0, 1, 4, 6, 9}) {
    INFO("level " << level);
    check_round_trip(block, level, compress2, zlib_uncompress());
  }
  check_round_trip(random_bytes(100000), 1, compress2, zlib_uncompress());
  check_round_trip(std::vector<Bytef>(1, 42), 1, compress2, zlib_uncompress());
}

TEST_CASE("what zlib writes, the stand-in uncompress reads back to the byte") {
  const std::vector<Bytef> block = exr_like_block();
  for (int level : {0, 1, 9}) {
    INFO("level " << level);
    check_round_trip(block, level, zlib_compress2(), uncompress);
  }
  check_round_trip(random_bytes(100000), 6, zlib_compress2(), uncompress);
}

TEST_CASE("compress (no level) writes zlib's default level's stream format, readable by zlib") {
  const std::vector<Bytef> block = exr_like_block();
  check_round_trip(block, Z_DEFAULT_COMPRESSION,
                   [](Bytef* d, uLongf* n, const Bytef* s, uLong m, int) { return compress(d, n, s, m); }, zlib_uncompress());
}

TEST_CASE("an output buffer too small for the data fails as zlib's does, with Z_BUF_ERROR") {
  const std::vector<Bytef> data = random_bytes(5000);
  std::vector<Bytef> small(100);
  uLongf size = static_cast<uLongf>(small.size());
  CHECK(compress2(small.data(), &size, data.data(), static_cast<uLong>(data.size()), 1) == Z_BUF_ERROR);

  std::vector<Bytef> packed(compressBound(static_cast<uLong>(data.size())));
  uLongf packed_size = static_cast<uLongf>(packed.size());
  REQUIRE(zlib_compress2()(packed.data(), &packed_size, data.data(), static_cast<uLong>(data.size()), 6) == Z_OK);
  std::vector<Bytef> short_out(data.size() - 1);
  uLongf out_size = static_cast<uLongf>(short_out.size());
  CHECK(uncompress(short_out.data(), &out_size, packed.data(), packed_size) == Z_BUF_ERROR);
}

TEST_CASE("a damaged stream fails as zlib's does: Z_DATA_ERROR for a wrong checksum, as zlib for a cut one") {
  const std::vector<Bytef> block = exr_like_block();
  std::vector<Bytef> packed(compressBound(static_cast<uLong>(block.size())));
  uLongf packed_size = static_cast<uLongf>(packed.size());
  REQUIRE(zlib_compress2()(packed.data(), &packed_size, block.data(), static_cast<uLong>(block.size()), 6) == Z_OK);
  std::vector<Bytef> out(block.size());

  std::vector<Bytef> bad_checksum(packed.begin(), packed.begin() + static_cast<std::ptrdiff_t>(packed_size));
  bad_checksum.back() ^= 0x5a;
  uLongf a = static_cast<uLongf>(out.size()), b = a;
  const int ours = uncompress(out.data(), &a, bad_checksum.data(), static_cast<uLong>(bad_checksum.size()));
  const int theirs = zlib_uncompress()(out.data(), &b, bad_checksum.data(), static_cast<uLong>(bad_checksum.size()));
  CHECK(ours == Z_DATA_ERROR);
  CHECK(ours == theirs);

  a = b = static_cast<uLongf>(out.size());
  const uLong cut = packed_size / 2;
  CHECK(uncompress(out.data(), &a, packed.data(), cut) == zlib_uncompress()(out.data(), &b, packed.data(), cut));
  CHECK(uncompress(out.data(), &a, packed.data(), cut) != Z_OK);
}

TEST_CASE("bytes after the end of the stream are read as zlib reads them") {
  const std::vector<Bytef> block = exr_like_block();
  std::vector<Bytef> packed(compressBound(static_cast<uLong>(block.size())) + 16);
  uLongf packed_size = static_cast<uLongf>(packed.size() - 16);
  REQUIRE(zlib_compress2()(packed.data(), &packed_size, block.data(), static_cast<uLong>(block.size()), 1) == Z_OK);
  const uLong with_tail = packed_size + 16;
  std::vector<Bytef> ours(block.size()), theirs(block.size());
  uLongf a = static_cast<uLongf>(ours.size()), b = a;
  CHECK(uncompress(ours.data(), &a, packed.data(), with_tail) == zlib_uncompress()(theirs.data(), &b, packed.data(), with_tail));
  CHECK(a == b);
  CHECK(ours == theirs);
}
