// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file SceneView.h
 * @brief A volume placed in the world and seen by a VTK-style camera, as the
 * renderer's frame: what the hosts without VTK (mediso-render, the web page)
 * share, so that their scenes match the ParaView mapper's.
 */
#ifndef MedicalIsosurfaces_SceneView_h
#define MedicalIsosurfaces_SceneView_h

#include "Camera.h"
#include "IsosurfaceFrame.h"

namespace mediso
{

/// Where a volume's points lie: point (i, j, k) at Origin + Direction (Spacing * (i, j, k)).
struct VolumePlacement
{
  int Dimensions[3] = { 2, 2, 2 };
  double Origin[3] = { 0.0, 0.0, 0.0 };
  double Spacing[3] = { 1.0, 1.0, 1.0 };
  /// Row-major 3x3: column a is the direction of index axis a.
  double Direction[9] = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };

  /// Index space (point (i, j, k) at (i, j, k)) to world space.
  matrix4::Matrix IndexToWorld() const;
  /// The world bounds of the volume's points (xmin, xmax, ymin, ymax, zmin, zmax).
  void Bounds(double bounds[6]) const;
};

/**
 * Sets the frame's matrices, near plane and viewport for `camera` looking at
 * `placement` in a `width` x `height` viewport, and its light to VTK's
 * default: a white headlight of intensity 1. The surfaces, material and
 * footprint options are left as they are.
 */
void SetFrameView(IsosurfaceFrame& frame, const Camera& camera, const VolumePlacement& placement,
  int width, int height);

} // namespace mediso

#endif
