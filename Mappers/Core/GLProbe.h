// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file GLProbe.h
 * @brief Can this context run the GPU core? A functional check (no VTK).
 *
 * GLApi::Load() checks the version and the functions; some drivers (remote,
 * software, old) still get integer textures or integer render targets
 * wrong. ProbeGL() does, on a tiny deterministic int16 volume with negative
 * values, what the pyramid's first level does: the volume as an RGBA16I 3D
 * texture (4 points to a texel along x), texelFetch from an isampler3D, one
 * full-screen pass of MedicalProbe_fs.glsl writing per cell column the
 * number of active cells (min < iso <= max) into an R32UI target, read back
 * with glReadPixels(GL_RGBA_INTEGER) and compared with the CPU, for three
 * isovalues. The pattern has no mirror symmetry and column counts 0 to 4,
 * so swapped or flipped axes, a normalised, unsigned or 8-bit reading of the
 * texture, or a constant output all give mismatches. The GL state is saved
 * and restored and every object released.
 */
#ifndef MedicalIsosurfaces_GLProbe_h
#define MedicalIsosurfaces_GLProbe_h

#include <string>

namespace mediso
{
class GLApi;

enum class ProbeResult
{
  Passed,         ///< the counts match: the GPU path can run
  MissingFeature, ///< the context cannot make what the probe needs (format, target)
  Failed          ///< it ran and gave wrong counts, or a shader does not build: a bug
};

/// Runs the probe in the current context of `gl`; `reason` says why it did not pass.
ProbeResult ProbeGL(const GLApi& gl, std::string& reason);

} // namespace mediso

#endif
