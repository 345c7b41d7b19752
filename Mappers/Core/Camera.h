// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file Camera.h
 * @brief A camera with VTK's conventions, for the hosts of the GPU core that have no VTK.
 *
 * mediso-render and the WebAssembly page must show a volume exactly as
 * ParaView does from the same parameters, so that their images can be
 * compared with the ParaView mapper's. This class states, in our own code,
 * what vtkRenderer::ResetCamera, vtkRenderer::ResetCameraClippingRange and
 * vtkCamera's Azimuth, Elevation, OrthogonalizeViewUp and Zoom do, with
 * VTK's defaults (view angle 30 degrees, looking down -z, view up +y,
 * clipping-range expansion 0.5), and gives the view and projection matrices
 * (row-major, column vectors; OpenGL's clip space).
 */
#ifndef MedicalIsosurfaces_Camera_h
#define MedicalIsosurfaces_Camera_h

#include "Matrix4.h"

namespace mediso
{

class Camera
{
public:
  double Position[3] = { 0.0, 0.0, 1.0 };
  double FocalPoint[3] = { 0.0, 0.0, 0.0 };
  double ViewUp[3] = { 0.0, 1.0, 0.0 };
  double ViewAngle = 30.0; ///< degrees, vertical
  bool Parallel = false;
  double ParallelScale = 1.0; ///< half the view's height, world units
  double ClippingRange[2] = { 0.01, 1000.01 };

  /// vtkRenderer::ResetCamera(bounds) for a viewport of `aspect` (width / height).
  void Reset(const double bounds[6], double aspect);
  /// vtkRenderer::ResetCameraClippingRange(bounds) (depth buffer deeper than 16 bits).
  void ResetClippingRange(const double bounds[6]);
  /// Rotation about the view up through the focal point (degrees).
  void Azimuth(double degrees);
  /// Rotation about the view's horizontal axis through the focal point (degrees).
  void Elevation(double degrees);
  /// Makes the view up perpendicular to the direction of projection.
  void OrthogonalizeViewUp();
  /// Narrows the view angle (perspective) or the parallel scale by `factor`.
  void Zoom(double factor);
  /// Moves the camera towards the focal point: the distance divided by `factor`.
  void Dolly(double factor);
  /// Sets position, focal point and view up at once (the view transform follows).
  void SetView(const double position[3], const double focalPoint[3], const double viewUp[3]);

  /// World to view space (the camera at the origin looking down -z).
  matrix4::Matrix ViewMatrix() const;
  /// View to clip space for a viewport of `aspect` (width / height).
  matrix4::Matrix ProjectionMatrix(double aspect) const;

private:
  void SetPosition(const double position[3]);
  matrix4::Matrix View = matrix4::Identity(); // as of the last SetPosition (as vtkCamera)
};

} // namespace mediso

#endif
