// zlib's one-shot compress, compress2 and uncompress, defined in the command line so that they stand
// in for zlib's (ELF symbol interposition, as a malloc replacement does) and made by libdeflate
// (Eric Biggers; Debian's libdeflate0), which writes and reads the same zlib streams about twice as
// fast: OpenEXR 3.1, which Debian 12 ships, (de)compresses every ZIP/ZIPS block of an EXR through
// these three calls (OpenEXR 3.2 moved to libdeflate itself for the same reason). On the 600 x 400
// street scene of docs/performance.md zlib was 16 % of a `lensmith bokeh` process's CPU time.
//
// Only whole-buffer calls are replaced; zlib's streaming API (libpng, libtiff) is untouched. Where
// libdeflate cannot do what zlib would (output that does not fit, a stream it rejects, trailing
// bytes), the call goes on to zlib's own function (dlsym RTLD_NEXT), so that results and error codes
// are zlib's in every case. The library, the tests and the Python module keep plain zlib.
#include <dlfcn.h>
#include <libdeflate.h>
#include <zlib.h>

#include <cstddef>
#include <memory>

namespace {

// zlib's level (Z_DEFAULT_COMPRESSION = -1 is zlib's 6) as libdeflate's: the same numbers, which
// libdeflate takes from 0 (stored) to 12.
int deflate_level(int zlib_level) { return zlib_level < 0 ? 6 : zlib_level > 9 ? 9 : zlib_level; }

struct CompressorFree {
  void operator()(libdeflate_compressor* c) const { libdeflate_free_compressor(c); }
};
struct DecompressorFree {
  void operator()(libdeflate_decompressor* d) const { libdeflate_free_decompressor(d); }
};

// One compressor per thread and level (OpenEXR compresses blocks on its own worker threads).
libdeflate_compressor* compressor(int level) {
  thread_local std::unique_ptr<libdeflate_compressor, CompressorFree> cache[10];
  auto& c = cache[level];
  if (!c) c.reset(libdeflate_alloc_compressor(level));
  return c.get();
}

libdeflate_decompressor* decompressor() {
  thread_local std::unique_ptr<libdeflate_decompressor, DecompressorFree> d(libdeflate_alloc_decompressor());
  return d.get();
}

template <class Function>
Function zlib_function(const char* name) {
  return reinterpret_cast<Function>(dlsym(RTLD_NEXT, name));
}

}  // namespace

extern "C" {

int compress2(Bytef* dest, uLongf* dest_len, const Bytef* source, uLong source_len, int level) {
  using Compress2 = int (*)(Bytef*, uLongf*, const Bytef*, uLong, int);
  if (level >= -1 && level <= 9) {
    if (libdeflate_compressor* c = compressor(deflate_level(level))) {
      const std::size_t written = libdeflate_zlib_compress(c, source, source_len, dest, *dest_len);
      if (written > 0) {
        *dest_len = static_cast<uLongf>(written);
        return Z_OK;
      }
    }
  }
  static const auto zlib_compress2 = zlib_function<Compress2>("compress2");
  return zlib_compress2 ? zlib_compress2(dest, dest_len, source, source_len, level) : Z_STREAM_ERROR;
}

int compress(Bytef* dest, uLongf* dest_len, const Bytef* source, uLong source_len) {
  return compress2(dest, dest_len, source, source_len, Z_DEFAULT_COMPRESSION);
}

int uncompress(Bytef* dest, uLongf* dest_len, const Bytef* source, uLong source_len) {
  using Uncompress = int (*)(Bytef*, uLongf*, const Bytef*, uLong);
  if (libdeflate_decompressor* d = decompressor()) {
    std::size_t in_used = 0, out_written = 0;
    if (libdeflate_zlib_decompress_ex(d, source, source_len, dest, *dest_len, &in_used, &out_written) == LIBDEFLATE_SUCCESS &&
        in_used == source_len) {
      *dest_len = static_cast<uLongf>(out_written);
      return Z_OK;
    }
  }
  static const auto zlib_uncompress = zlib_function<Uncompress>("uncompress");
  return zlib_uncompress ? zlib_uncompress(dest, dest_len, source, source_len) : Z_STREAM_ERROR;
}

}  // extern "C"
