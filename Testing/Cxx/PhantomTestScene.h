// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file PhantomTestScene.h
 * @brief The scene the GPU core's session tests draw: mediso-render's head
 * phantom (headless::MakePhantom) as an IsosurfaceScene volume, its placement,
 * a camera turned 30 degrees in azimuth and 20 in elevation to see both
 * surfaces, and the page's two looks (a translucent skin at -500 over the bone
 * at 400).
 *
 * @code
 * medical_test::PhantomTestScene phantom;
 * if (!phantom.Make(64, Width, Height, error)) { ... }
 * scene.SetVolume(phantom.Volume, error);
 * mediso::SetFrameView(frame, phantom.View, phantom.Placement, Width, Height);
 * @endcode
 */
#ifndef PhantomTestScene_h
#define PhantomTestScene_h

#include "Camera.h"
#include "IsosurfaceFrame.h"
#include "SceneView.h"
#include "VolumeSources.h"

#include <algorithm>
#include <string>

namespace medical_test
{
struct PhantomTestScene
{
  mediso::headless::MetaImage Image; // the values Volume points into
  mediso::VolumeDescription Volume;
  mediso::VolumePlacement Placement;
  mediso::Camera View;

  /// The phantom of `size` points a side, seen in a `width` x `height` view; false with the reason.
  bool Make(int size, int width, int height, std::string& error)
  {
    if (!mediso::headless::MakePhantom(size, this->Image, error))
    {
      return false;
    }
    this->Volume.Type = this->Image.Type;
    this->Volume.Data = this->Image.Bytes.data();
    std::copy(this->Image.Dimensions, this->Image.Dimensions + 3, this->Volume.Dims);
    std::copy(this->Image.Dimensions, this->Image.Dimensions + 3, this->Placement.Dimensions);
    std::copy(this->Image.Spacing, this->Image.Spacing + 3, this->Placement.Spacing);
    double bounds[6];
    this->Placement.Bounds(bounds);
    this->View.Reset(bounds, static_cast<double>(width) / height);
    this->View.Azimuth(30.0);
    this->View.Elevation(20.0);
    this->View.OrthogonalizeViewUp();
    this->View.ResetClippingRange(bounds);
    return true;
  }
};

/// The page's skin (-500, skin-coloured, at `opacity`).
inline mediso::IsosurfaceLook PhantomSkin(float opacity)
{
  mediso::IsosurfaceLook skin;
  skin.Value = -500.0;
  skin.Color[0] = 0.93f;
  skin.Color[1] = 0.75f;
  skin.Color[2] = 0.62f;
  skin.Opacity = opacity;
  return skin;
}

/// The page's bone (400, opaque, the default colour).
inline mediso::IsosurfaceLook PhantomBone()
{
  mediso::IsosurfaceLook bone;
  bone.Value = 400.0;
  return bone;
}
} // namespace medical_test

#endif
