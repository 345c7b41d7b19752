// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file HeadPhantom.h
 * @brief A deterministic, resolution-independent CT head phantom (no VTK).
 *
 * The phantom is a painter's-order stack of axis-aligned ellipsoids, each with a
 * tissue value in Hounsfield-like units (air -1000, soft tissue ~40, cortical
 * bone ~1000-1200, CSF ~5, ...). It is defined on the normalised cube
 * [-1, 1]^3 that is mapped onto the whole grid, so any grid resolution shows
 * the same head: a 32^3 grid is a coarse sampling of the same field as 1024^3.
 *
 * Boundaries are smooth: each ellipsoid blends into what lies below it over a
 * band of half-width `w` around its surface (a cubic smoothstep of a first-order
 * signed distance estimate), so isosurfaces of the field are smooth surfaces and
 * not voxel staircases. `w` is the larger of a fixed physical width and 1.5
 * grid steps, which keeps coarse grids free of aliasing.
 *
 * Evaluation is row-based: along one x-row an ellipsoid covers an interval that
 * has a closed form, and only the voxels in its boundary band need the smooth
 * blend; voxels fully inside are assigned directly. The cost is therefore close
 * to one write per voxel plus the boundary voxels, which is what makes 1024^3
 * phantoms practical.
 *
 * Optional noise: zero-mean, approximately Gaussian, drawn from a hash of the
 * voxel's global (i, j, k) index and the seed. It does not depend on how the
 * grid is split across threads or MPI pieces: any sub-extent of a grid holds
 * exactly the values the whole grid holds there.
 *
 * This header and its implementation include nothing from VTK so that the
 * algorithm can be unit-tested on its own (see Testing/Cxx/TestHeadPhantomCore.cxx).
 */
#ifndef MedicalIsosurfaces_HeadPhantom_h
#define MedicalIsosurfaces_HeadPhantom_h

#include <cstdint>
#include <string>
#include <vector>

namespace mediso
{

/// One tissue region: an axis-aligned ellipsoid in normalised coordinates.
struct PhantomEllipsoid
{
  const char* Tissue; ///< Human-readable tissue name.
  double Center[3];   ///< Centre in [-1, 1]^3.
  double Axes[3];     ///< Semi-axes (normalised units).
  double Value;       ///< Tissue value in Hounsfield units.
};

/// Tissue values (HU) used by the default head. Public so that tests and
/// scripts can choose isovalues between them.
struct PhantomHU
{
  static constexpr double Air = -1000.0;
  static constexpr double Scalp = 40.0;
  static constexpr double Bone = 1100.0;
  static constexpr double Vertebra = 800.0;
  static constexpr double CSF = 5.0;
  static constexpr double Brain = 35.0;
  static constexpr double Eye = 15.0;
  static constexpr double Lesion = 70.0;
  static constexpr double Calcification = 600.0;
};

class HeadPhantom
{
public:
  /// Grid size in points along x, y, z (each >= 2). Validate() checks them.
  HeadPhantom(const int dimensions[3], double noiseStdDev, std::uint32_t seed);

  /// Returns an empty string when the parameters describe a valid phantom,
  /// otherwise a sentence saying what is wrong.
  std::string Validate() const;

  /// Number of points, as a 64-bit count (the product may not fit in int).
  std::int64_t GetNumberOfPoints() const;

  /// The ellipsoids, in painting order (later ones overwrite earlier ones).
  const std::vector<PhantomEllipsoid>& GetRegions() const { return this->Regions; }

  /**
   * Fill the rows k in [kBegin, kEnd) of a sub-extent of the grid.
   * `extent` = {i0, i1, j0, j1, k0, k1} (inclusive, inside [0, dim-1]);
   * `out` points at the sample (i0, j0, k0) and holds the sub-extent
   * x-fastest, contiguous. Thread-safe: distinct k ranges may be filled
   * concurrently. `rowScratch` must hold (i1 - i0 + 1) doubles.
   */
  void FillSlices(const int extent[6], int kBegin, int kEnd, std::int16_t* out,
    double* rowScratch) const;

  /// The field at one grid point, without the row optimisation (reference
  /// for tests; noise included).
  std::int16_t EvaluatePoint(int i, int j, int k) const;

  /// The noise-free field at a point of the normalised cube.
  double EvaluateContinuous(double x, double y, double z) const;

private:
  double ToNormalized(int index, int axis) const;
  double Noise(int i, int j, int k) const;
  std::int16_t Quantize(double value, int i, int j, int k) const;
  double BlendWidth() const;

  int Dimensions[3];
  double NoiseStdDev;
  std::uint32_t Seed;
  double HalfWidth;
  std::vector<PhantomEllipsoid> Regions;
};

} // namespace mediso

#endif
