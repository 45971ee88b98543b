// The frame's Cryptomatte mattes (render/cryptomatte.h): which names a scene
// can show and how one camera sample's first hit shares its weight among
// them. CryptoMaterial: the land classes by their coverage channel's name
// (render/coverage.h: a rule's `name`, else its preset's, ...; a terrain
// point's shares sum to 1), and on objects their object layers (snow) and,
// for the rest, the object's material (its preset, else its own name).
// CryptoObject: "terrain" (the DEM and the ground beyond it) and each
// object by name. The sky is ID 0 in both.
#pragma once

#include <string>
#include <vector>

#include "render/coverage.h"
#include "render/cryptomatte.h"

namespace drift::render {

class TerrainScene;
struct SceneInput;

// The name of object `i` of the scene: input.object_names[i], else
// "object<i + 1>".
std::string object_name(const SceneInput& input, std::size_t i);

class FrameMattes {
 public:
  FrameMattes(const TerrainScene& scene, const SceneInput& input);

  const CryptomatteLayer& material() const { return material_; }
  const CryptomatteLayer& object() const { return object_; }

  // Weights of one pixel, summed over its samples.
  struct Weights {
    std::vector<float> material, object;
    float empty = 0.0f;  // samples that saw the sky
  };
  Weights weights() const;
  // Adds one sample: `object` -1 (the sky), 0 (the terrain) or k + 1
  // (object k); `coverage` its hit's shares (render/coverage.h).
  void add(Weights& w, int object, const Coverage& coverage) const;
  // The pixel's (ID, coverage) pairs of both layers, material then object,
  // from the sums of `samples` samples: 2 x (ranks of each) floats.
  void write(const Weights& w, int samples, float* out) const;
  int channel_count() const { return 2 * (material_.ranks + object_.ranks); }

 private:
  CryptomatteLayer material_, object_;
  std::vector<float> material_ids_, object_ids_;
  int coverage_count_ = 0;            // the first names are the coverage channels'
  std::vector<int> object_material_;  // by object: its material's index
  std::vector<int> object_index_;     // by object: its name's index in object_
};

}  // namespace drift::render
