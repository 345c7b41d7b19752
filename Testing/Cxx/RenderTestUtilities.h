// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file RenderTestUtilities.h
 * @brief What the image tests share: a panel of a window that shows one
 * surface, the comparison of the window with the test's baseline, and the
 * comparison of two images of the same scene drawn two ways.
 *
 * @code
 * const double bone[3] = { 0.96, 0.94, 0.86 }, eye[3] = { -0.35, 1.0, 0.15 };
 * medical_test::AddSurfacePanel(renWin, contour->GetOutputPort(), bone, 0, 2, eye);
 * renWin->Render();
 * return !medical_test::CompareWithBaseline(argc, argv, renWin);
 * @endcode
 */
#ifndef RenderTestUtilities_h
#define RenderTestUtilities_h

#include "vtkActor.h"
#include "vtkAlgorithmOutput.h"
#include "vtkCamera.h"
#include "vtkNew.h"
#include "vtkPolyDataMapper.h"
#include "vtkProperty.h"
#include "vtkRegressionTestImage.h"
#include "vtkRenderWindow.h"
#include "vtkRenderWindowInteractor.h"
#include "vtkRenderer.h"

#include <algorithm>
#include <cstdlib>
#include <vector>

namespace medical_test
{
/**
 * Adds to `window` a renderer that fills column `column` of `columns` and
 * shows the surface of `surface` in `color` (a little specular, the tests'
 * dark background), seen from `eye` towards the origin, head up (+z), the
 * camera then reset to the surface. Returns the renderer (the window holds
 * it), for a test that moves the camera closer.
 */
inline vtkRenderer* AddSurfacePanel(vtkRenderWindow* window, vtkAlgorithmOutput* surface,
  const double color[3], int column, int columns, const double eye[3])
{
  vtkNew<vtkPolyDataMapper> mapper;
  mapper->SetInputConnection(surface);
  mapper->ScalarVisibilityOff();
  vtkNew<vtkActor> actor;
  actor->SetMapper(mapper);
  actor->GetProperty()->SetColor(color[0], color[1], color[2]);
  actor->GetProperty()->SetSpecular(0.2);
  vtkNew<vtkRenderer> renderer;
  const double width = 1.0 / columns;
  renderer->SetViewport(width * column, 0.0, width * (column + 1), 1.0);
  renderer->SetBackground(0.1, 0.12, 0.16);
  renderer->AddActor(actor);
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetFocalPoint(0, 0, 0);
  camera->SetPosition(eye[0], eye[1], eye[2]);
  camera->SetViewUp(0, 0, 1);
  renderer->ResetCamera();
  window->AddRenderer(renderer);
  return renderer;
}

/**
 * vtkRegressionTestImage as a function: compares `window` with the test's
 * baseline image (named by the test's arguments) and, when the arguments ask
 * for it (-I), hands the window to an interactor. Returns vtkRegressionTester's
 * result (FAILED, PASSED, NOT_RUN or DO_INTERACTOR).
 */
inline int CompareWithBaseline(int argc, char* argv[], vtkRenderWindow* window)
{
  const int result = vtkRegressionTestImage(window);
  if (result == vtkRegressionTester::DO_INTERACTOR)
  {
    vtkNew<vtkRenderWindowInteractor> iren;
    iren->SetRenderWindow(window);
    iren->Start();
  }
  return result;
}
/// How two RGB images of one scene agree (see CompareImages()).
struct ImageAgreement
{
  int Either = 0;               ///< pixels covered (not black) in either image
  double Agreement = 0.0;       ///< share of those covered in both
  double MeanDifference = 255.0; ///< mean colour difference (0..255) over the pixels both cover
  int Differing = 0;            ///< pixels whose colour differs by more than 24 in a channel
};

/// Compares two RGB images (3 bytes a pixel, same size) pixel by pixel.
inline ImageAgreement CompareImages(
  const std::vector<unsigned char>& a, const std::vector<unsigned char>& b)
{
  int either = 0, both = 0, disagree = 0, differing = 0;
  double diff = 0.0;
  for (std::size_t p = 0; p + 2 < a.size() && p + 2 < b.size(); p += 3)
  {
    const bool ca = a[p] > 0 || a[p + 1] > 0 || a[p + 2] > 0;
    const bool cb = b[p] > 0 || b[p + 1] > 0 || b[p + 2] > 0;
    either += ca || cb;
    disagree += ca != cb;
    int largest = 0;
    for (int c = 0; c < 3; ++c)
    {
      largest = std::max(largest, std::abs(static_cast<int>(a[p + c]) - static_cast<int>(b[p + c])));
    }
    differing += largest > 24;
    if (ca && cb)
    {
      ++both;
      for (int c = 0; c < 3; ++c)
      {
        diff += std::abs(static_cast<int>(a[p + c]) - static_cast<int>(b[p + c]));
      }
    }
  }
  ImageAgreement result;
  result.Either = either;
  result.Agreement = either ? 1.0 - static_cast<double>(disagree) / either : 0.0;
  result.MeanDifference = both ? diff / (3.0 * both) : 255.0;
  result.Differing = differing;
  return result;
}
} // namespace medical_test

#endif
