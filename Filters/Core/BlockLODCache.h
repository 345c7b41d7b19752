// SPDX-License-Identifier: BSD-3-Clause
/**
 * @file BlockLODCache.h
 * @brief The (isovalue, level) surface cache of the block LOD method: least
 * recently used surfaces go first when the cache holds more than its byte
 * limit (no VTK).
 *
 * The cache holds whatever a host calls a surface (vtkBlockLODContour: a
 * vtkPolyData; a WebAssembly host: its buffers), with the bytes the host says
 * it holds. Find() marks an entry used; Insert() adds or replaces one as the
 * most recently used; Evict() drops least recently used entries until the
 * total fits the limit, never one of the keys the host still needs (those of
 * its current output), so the current output may exceed the limit alone.
 */
#ifndef MedicalIsosurfaces_BlockLODCache_h
#define MedicalIsosurfaces_BlockLODCache_h

#include "BlockLOD.h"

#include <algorithm>
#include <iterator>
#include <list>
#include <map>
#include <utility>
#include <vector>

namespace mediso
{

template <typename Surface>
class SurfaceCache
{
public:
  /// The surface of a pair, marked most recently used; null when not cached.
  Surface* Find(const SurfaceKey& key)
  {
    auto it = this->Index.find(key);
    if (it == this->Index.end())
    {
      return nullptr;
    }
    this->Order.splice(this->Order.end(), this->Order, it->second);
    return &it->second->Value;
  }

  /// True when the pair is cached (does not mark it used).
  bool Contains(const SurfaceKey& key) const { return this->Index.count(key) > 0; }

  /// Adds (or replaces) a pair's surface as the most recently used.
  void Insert(const SurfaceKey& key, Surface surface, double bytes)
  {
    this->Erase(key);
    this->Order.push_back(Entry{ key, std::move(surface), bytes });
    this->Index[key] = std::prev(this->Order.end());
    this->Total += bytes;
  }

  /// Removes a pair; false when it was not cached.
  bool Erase(const SurfaceKey& key)
  {
    auto it = this->Index.find(key);
    if (it == this->Index.end())
    {
      return false;
    }
    this->Total -= it->second->Bytes;
    this->Order.erase(it->second);
    this->Index.erase(it);
    return true;
  }

  /// Drops least recently used pairs, except those in `keep`, until the cache
  /// holds at most `limitBytes`. Returns the dropped keys in the order dropped;
  /// their surfaces are moved to `surfaces` when given (a host may reuse
  /// their memory), else destroyed.
  std::vector<SurfaceKey> Evict(double limitBytes, const std::vector<SurfaceKey>& keep = {},
    std::vector<Surface>* surfaces = nullptr)
  {
    std::vector<SurfaceKey> dropped;
    for (auto it = this->Order.begin(); this->Total > limitBytes && it != this->Order.end();)
    {
      if (std::find(keep.begin(), keep.end(), it->Key) != keep.end())
      {
        ++it;
        continue;
      }
      dropped.push_back(it->Key);
      if (surfaces)
      {
        surfaces->push_back(std::move(it->Value));
      }
      this->Total -= it->Bytes;
      this->Index.erase(it->Key);
      it = this->Order.erase(it);
    }
    if (this->Order.empty())
    {
      this->Total = 0; // no rounding left behind
    }
    return dropped;
  }

  void Clear()
  {
    this->Order.clear();
    this->Index.clear();
    this->Total = 0;
  }

  /// Bytes of all cached surfaces.
  double GetBytes() const { return this->Total; }
  /// Bytes of one pair's surface (0 when not cached).
  double EntryBytes(const SurfaceKey& key) const
  {
    auto it = this->Index.find(key);
    return it == this->Index.end() ? 0.0 : it->second->Bytes;
  }
  std::size_t GetSize() const { return this->Order.size(); }

  /// Cached keys from least to most recently used (the eviction order).
  std::vector<SurfaceKey> GetKeysByAge() const
  {
    std::vector<SurfaceKey> keys;
    for (const Entry& e : this->Order)
    {
      keys.push_back(e.Key);
    }
    return keys;
  }

private:
  struct Entry
  {
    SurfaceKey Key;
    Surface Value;
    double Bytes;
  };
  std::list<Entry> Order; // least recently used first
  std::map<SurfaceKey, typename std::list<Entry>::iterator> Index;
  double Total = 0;
};

} // namespace mediso

#endif
