// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file PngWriter.h
 * @brief Writes an 8-bit RGB image as a PNG file (zlib only, no VTK).
 */
#ifndef MedicalIsosurfaces_PngWriter_h
#define MedicalIsosurfaces_PngWriter_h

#include <string>
#include <vector>

namespace mediso
{
namespace headless
{
/**
 * Writes `rgba` (width x height, 4 bytes per pixel, the first row the
 * bottom one, as glReadPixels gives them) to `path` as an RGB PNG, top row
 * first. False with the reason in @a error.
 */
bool WritePng(const std::string& path, int width, int height, const std::vector<unsigned char>& rgba,
  std::string& error);
} // namespace headless
} // namespace mediso

#endif
