#include "deep_exr_writer.h"

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfDeepFrameBuffer.h>
#include <OpenEXR/ImfDeepScanLineOutputFile.h>
#include <OpenEXR/ImfDeepTiledOutputFile.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfPartType.h>
#include <OpenEXR/ImfTileDescription.h>

namespace lensmith::testing {

void write_deep_exr(const std::filesystem::path& path, int width, int height, const std::vector<std::string>& names,
                    const std::vector<std::vector<std::vector<float>>>& pixels, int tile_px, int display_width,
                    int display_height, int data_x, int data_y) {
  const Imath::Box2i display(Imath::V2i(0, 0), Imath::V2i((display_width > 0 ? display_width : width) - 1,
                                                          (display_height > 0 ? display_height : height) - 1));
  const Imath::Box2i data(Imath::V2i(data_x, data_y), Imath::V2i(data_x + width - 1, data_y + height - 1));
  Imf::Header header(display, data);
  // OpenEXR addresses the buffers in absolute pixel coordinates: their bases go back to (0, 0).
  const std::ptrdiff_t origin = static_cast<std::ptrdiff_t>(data_y) * width + data_x;
  header.setType(tile_px > 0 ? Imf::DEEPTILE : Imf::DEEPSCANLINE);
  header.compression() = Imf::ZIPS_COMPRESSION;
  if (tile_px > 0) header.setTileDescription(Imf::TileDescription(static_cast<unsigned>(tile_px), static_cast<unsigned>(tile_px)));
  for (const std::string& n : names) header.channels().insert(n, Imf::Channel(Imf::FLOAT));
  const auto count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  std::vector<unsigned int> counts(count);
  // Per channel, per pixel: the samples' values, and the pointers OpenEXR reads them through.
  std::vector<std::vector<std::vector<float>>> values(names.size(), std::vector<std::vector<float>>(count));
  std::vector<std::vector<float*>> pointers(names.size(), std::vector<float*>(count, nullptr));
  for (std::size_t p = 0; p < count; ++p) {
    counts[p] = static_cast<unsigned int>(pixels[p].size());
    for (std::size_t c = 0; c < names.size(); ++c) {
      for (const std::vector<float>& sample : pixels[p]) values[c][p].push_back(sample[c]);
      pointers[c][p] = values[c][p].data();
    }
  }
  Imf::DeepFrameBuffer frame;
  frame.insertSampleCountSlice(Imf::Slice(Imf::UINT, reinterpret_cast<char*>(counts.data() - origin), sizeof(unsigned int),
                                          static_cast<std::size_t>(width) * sizeof(unsigned int)));
  for (std::size_t c = 0; c < names.size(); ++c) {
    frame.insert(names[c], Imf::DeepSlice(Imf::FLOAT, reinterpret_cast<char*>(pointers[c].data() - origin), sizeof(float*),
                                          static_cast<std::size_t>(width) * sizeof(float*), sizeof(float)));
  }
  if (tile_px > 0) {
    Imf::DeepTiledOutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writeTiles(0, out.numXTiles() - 1, 0, out.numYTiles() - 1);
  } else {
    Imf::DeepScanLineOutputFile out(path.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(height);
  }
}

}  // namespace lensmith::testing
