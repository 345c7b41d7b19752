// SPDX-License-Identifier: BSD-3-Clause
// Unit test of the VTK-free (isovalue, level) surface cache
// (Filters/Core/BlockLODCache.h), without VTK:
// - eviction order is least recently used first, Find() marks an entry used;
// - Evict() stops as soon as the bytes fit the limit and never drops a kept key;
// - replacing an entry updates the bytes; Erase/Clear/EntryBytes agree;
// - a long random sequence of inserts, finds and evictions matches a simple
//   reference model (a use counter per entry, the smallest evicted first);
// - the cache holds move-only surfaces.
#include "MedicalTestUtilities.h"
#include "BlockLODCache.h"

#include <cstdio>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace
{
using medical_test::Check;
using mediso::SurfaceKey;

std::string Text(const std::vector<SurfaceKey>& keys)
{
  std::string s;
  for (const SurfaceKey& k : keys)
  {
    s += "(" + std::to_string(k.Isovalue) + "," + std::to_string(k.Level) + ")";
  }
  return s;
}

void TestOrder()
{
  mediso::SurfaceCache<int> cache;
  const SurfaceKey a{ 100, 0 }, b{ 100, 3 }, c{ -500, 2 };
  cache.Insert(a, 1, 10);
  cache.Insert(b, 2, 20);
  cache.Insert(c, 3, 30);
  Check(cache.GetBytes() == 60 && cache.GetSize() == 3, "three entries, 60 bytes");
  Check(cache.GetKeysByAge() == std::vector<SurfaceKey>{ a, b, c }, "insertion order is age order");
  int* found = cache.Find(a);
  Check(found && *found == 1, "Find returns the surface");
  Check(cache.GetKeysByAge() == std::vector<SurfaceKey>{ b, c, a }, "Find makes an entry newest");
  Check(cache.Find(SurfaceKey{ 100, 1 }) == nullptr, "a pair not cached is not found");
  Check(cache.Contains(b) && !cache.Contains(SurfaceKey{ 100, 2 }), "Contains");
  Check(cache.GetKeysByAge() == std::vector<SurfaceKey>{ b, c, a }, "Contains does not touch");

  // Over a limit of 50: only the oldest (b) goes, then the cache fits.
  std::vector<SurfaceKey> dropped = cache.Evict(50);
  Check(dropped == std::vector<SurfaceKey>{ b }, "evicts the least recently used first: " + Text(dropped));
  Check(cache.GetBytes() == 40, "40 bytes left");
  dropped = cache.Evict(40);
  Check(dropped.empty(), "nothing goes when the bytes fit the limit");

  // Kept keys survive even over the limit; the others go oldest first.
  cache.Insert(b, 2, 20);
  dropped = cache.Evict(0, { a });
  Check(dropped == (std::vector<SurfaceKey>{ c, b }), "kept keys skipped, others by age: " + Text(dropped));
  Check(cache.GetSize() == 1 && cache.Contains(a) && cache.GetBytes() == 10,
    "the kept entry stays although over the limit");

  // Replacing an entry replaces its bytes and makes it newest.
  cache.Insert(c, 3, 30);
  cache.Insert(a, 7, 15);
  Check(cache.GetBytes() == 45 && cache.EntryBytes(a) == 15 && *cache.Find(a) == 7,
    "replacing an entry replaces its surface and bytes");
  Check(cache.GetKeysByAge() == std::vector<SurfaceKey>{ c, a }, "a replaced entry is newest");
  Check(cache.Erase(c) && !cache.Erase(c) && cache.GetBytes() == 15, "Erase");
  Check(cache.EntryBytes(c) == 0, "EntryBytes of a pair not cached is 0");
  cache.Clear();
  Check(cache.GetSize() == 0 && cache.GetBytes() == 0, "Clear empties the cache");
  Check(cache.Evict(0).empty(), "evicting an empty cache drops nothing");
}

// Random operations against a reference: entries with a last-use counter;
// eviction removes the smallest counter not kept while the total is over.
void TestRandom()
{
  struct Ref
  {
    double Bytes;
    int Value;
    long Use;
  };
  std::map<SurfaceKey, Ref> ref;
  long clock = 0;
  mediso::SurfaceCache<int> cache;
  std::mt19937 rng(12345);
  std::uniform_int_distribution<int> op(0, 9), iso(0, 11), level(0, 3), bytes(1, 50);
  int mismatches = 0;
  for (int step = 0; step < 20000; ++step)
  {
    const SurfaceKey key{ 10.0 * iso(rng), level(rng) };
    const int o = op(rng);
    if (o < 4)
    {
      const double b = bytes(rng);
      cache.Insert(key, step, b);
      ref[key] = Ref{ b, step, ++clock };
    }
    else if (o < 8)
    {
      int* got = cache.Find(key);
      auto it = ref.find(key);
      if ((got == nullptr) != (it == ref.end()) || (got && *got != it->second.Value))
      {
        ++mismatches;
      }
      if (it != ref.end())
      {
        it->second.Use = ++clock;
      }
    }
    else
    {
      const double limit = 20.0 * level(rng) * level(rng);
      std::vector<SurfaceKey> keep;
      if (o == 9)
      {
        keep.push_back(key);
      }
      std::vector<SurfaceKey> expected;
      double total = 0;
      for (const auto& e : ref)
      {
        total += e.second.Bytes;
      }
      while (total > limit)
      {
        auto victim = ref.end();
        for (auto it = ref.begin(); it != ref.end(); ++it)
        {
          if (!(it->first == key && o == 9) &&
            (victim == ref.end() || it->second.Use < victim->second.Use))
          {
            victim = it;
          }
        }
        if (victim == ref.end())
        {
          break;
        }
        total -= victim->second.Bytes;
        expected.push_back(victim->first);
        ref.erase(victim);
      }
      if (cache.Evict(limit, keep) != expected)
      {
        ++mismatches;
      }
    }
    double total = 0;
    for (const auto& e : ref)
    {
      total += e.second.Bytes;
    }
    if (cache.GetSize() != ref.size() || std::abs(cache.GetBytes() - total) > 1e-9)
    {
      ++mismatches;
    }
  }
  std::printf("random sequence of 20000 operations: %d mismatches with the reference\n", mismatches);
  Check(mismatches == 0, "the cache behaves as the reference LRU model");
}

void TestMoveOnly()
{
  mediso::SurfaceCache<std::unique_ptr<int>> cache;
  cache.Insert(SurfaceKey{ 1, 1 }, std::make_unique<int>(42), 8);
  std::unique_ptr<int>* p = cache.Find(SurfaceKey{ 1, 1 });
  Check(p && **p == 42, "a move-only surface is held and found");
}
} // namespace

int main()
{
  TestOrder();
  TestRandom();
  TestMoveOnly();
  return medical_test::Finish("BlockLOD surface cache: all checks passed");
}
