// SPDX-License-Identifier: BSD-3-Clause
#include "IsoThresholds.h"

#include <cfloat>
#include <cmath>
#include <limits>

namespace mediso
{

ValueKind ValueKindOf(ScalarType type)
{
  switch (type)
  {
    case ScalarType::Int8:
    case ScalarType::Int16:
    case ScalarType::Int32:
      return ValueKind::Signed;
    case ScalarType::UInt8:
    case ScalarType::UInt16:
    case ScalarType::UInt32:
      return ValueKind::Unsigned;
    default:
      return ValueKind::Float;
  }
}

std::string ValueKindDefines(ValueKind kind)
{
  switch (kind)
  {
    case ValueKind::Signed:
      return "#define VALUE_SAMPLER isampler3D\n#define VALUE_TYPE int\n#define VALUE_VEC4 ivec4\n";
    case ValueKind::Unsigned:
      return "#define VALUE_SAMPLER usampler3D\n#define VALUE_TYPE uint\n#define VALUE_VEC4 uvec4\n";
    case ValueKind::Float:
    default:
      return "#define VALUE_SAMPLER sampler3D\n#define VALUE_TYPE float\n#define VALUE_VEC4 "
             "vec4\n#define VALUE_IS_FLOAT 1\n";
  }
}

bool IsoThresholds::Crosses(double lo, double hi) const
{
  for (int t = 0; t < this->Count; ++t)
  {
    double v;
    switch (this->Kind)
    {
      case ValueKind::Signed:
        v = this->Ints[t];
        break;
      case ValueKind::Unsigned:
        v = this->UInts[t];
        break;
      default:
        v = this->Floats[t];
        break;
    }
    if (lo < v && v <= hi)
    {
      return true;
    }
  }
  return false;
}

IsoThresholds MakeIsoThresholds(ScalarType type, const std::vector<double>& isovalues)
{
  IsoThresholds t;
  t.Kind = ValueKindOf(type);
  double typeMin = 0.0, typeMax = 0.0;
  VisitScalarType(type,
    [&](auto v)
    {
      using T = decltype(v);
      typeMin = static_cast<double>(std::numeric_limits<T>::lowest());
      typeMax = static_cast<double>(std::numeric_limits<T>::max());
    });
  for (std::size_t index = 0; index < isovalues.size(); ++index)
  {
    const double iso = isovalues[index];
    if (std::isnan(iso))
    {
      continue;
    }
    if (t.Kind == ValueKind::Float)
    {
      // The smallest float not below iso (+inf above the float range).
      float value;
      if (iso > static_cast<double>(FLT_MAX))
      {
        value = std::numeric_limits<float>::infinity();
      }
      else if (iso < -static_cast<double>(FLT_MAX))
      {
        value = -FLT_MAX;
      }
      else
      {
        value = static_cast<float>(iso);
        if (static_cast<double>(value) < iso)
        {
          value = std::nextafter(value, std::numeric_limits<float>::infinity());
        }
      }
      t.Floats.push_back(value);
    }
    else
    {
      // For integers v: v < iso <=> v < ceil(iso), iso <= v <=> ceil(iso) <= v.
      // A threshold above the maximum, or at or below the minimum, never
      // satisfies min < t <= max.
      const double c = std::ceil(iso);
      if (c > typeMax || c <= typeMin)
      {
        continue;
      }
      if (t.Kind == ValueKind::Signed)
      {
        t.Ints.push_back(static_cast<std::int32_t>(c));
      }
      else
      {
        t.UInts.push_back(static_cast<std::uint32_t>(c));
      }
    }
    t.Indices.push_back(static_cast<int>(index));
    ++t.Count;
  }
  return t;
}

} // namespace mediso
