// SPDX-License-Identifier: BSD-3-Clause
#include "PngWriter.h"

#include <zlib.h>

#include <cstdint>
#include <cstdio>

namespace mediso
{
namespace headless
{
namespace
{
void PutUInt32(std::vector<unsigned char>& out, std::uint32_t v)
{
  out.push_back(static_cast<unsigned char>(v >> 24));
  out.push_back(static_cast<unsigned char>(v >> 16));
  out.push_back(static_cast<unsigned char>(v >> 8));
  out.push_back(static_cast<unsigned char>(v));
}

// A chunk: length, type, data, CRC of type and data.
void PutChunk(std::vector<unsigned char>& out, const char type[4], const unsigned char* data,
  std::size_t size)
{
  PutUInt32(out, static_cast<std::uint32_t>(size));
  const std::size_t at = out.size();
  out.insert(out.end(), type, type + 4);
  out.insert(out.end(), data, data + size);
  const uLong crc = crc32(0L, out.data() + at, static_cast<uInt>(size + 4));
  PutUInt32(out, static_cast<std::uint32_t>(crc));
}
} // namespace

bool WritePng(const std::string& path, int width, int height, const std::vector<unsigned char>& rgba,
  std::string& error)
{
  if (width <= 0 || height <= 0 ||
    rgba.size() != static_cast<std::size_t>(width) * static_cast<std::size_t>(height) * 4)
  {
    error = "no image to write";
    return false;
  }
  // Scanlines top first, each with filter byte 0 (none).
  const std::size_t row = 1 + 3 * static_cast<std::size_t>(width);
  std::vector<unsigned char> raw(row * static_cast<std::size_t>(height));
  for (int y = 0; y < height; ++y)
  {
    unsigned char* line = raw.data() + row * y;
    const unsigned char* from = rgba.data() + 4 * static_cast<std::size_t>(width) * (height - 1 - y);
    line[0] = 0;
    for (int x = 0; x < width; ++x)
    {
      line[1 + 3 * x] = from[4 * x];
      line[2 + 3 * x] = from[4 * x + 1];
      line[3 + 3 * x] = from[4 * x + 2];
    }
  }
  uLongf packedSize = compressBound(static_cast<uLong>(raw.size()));
  std::vector<unsigned char> packed(packedSize);
  if (compress2(packed.data(), &packedSize, raw.data(), static_cast<uLong>(raw.size()), 6) != Z_OK)
  {
    error = "compressing the image failed";
    return false;
  }
  std::vector<unsigned char> png = { 0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n' };
  std::vector<unsigned char> header;
  PutUInt32(header, static_cast<std::uint32_t>(width));
  PutUInt32(header, static_cast<std::uint32_t>(height));
  header.insert(header.end(), { 8, 2, 0, 0, 0 }); // 8 bits, RGB, deflate, no filter, no interlace
  PutChunk(png, "IHDR", header.data(), header.size());
  PutChunk(png, "IDAT", packed.data(), packedSize);
  PutChunk(png, "IEND", nullptr, 0);
  std::FILE* file = std::fopen(path.c_str(), "wb");
  if (!file)
  {
    error = path + ": cannot be written";
    return false;
  }
  const bool written = std::fwrite(png.data(), 1, png.size(), file) == png.size();
  const bool closed = std::fclose(file) == 0;
  if (!written || !closed)
  {
    error = path + ": writing failed";
    return false;
  }
  return true;
}
} // namespace headless
} // namespace mediso
