#include "render/mattes.h"

#include <algorithm>

#include "render/render_settings.h"
#include "render/terrain_scene.h"

namespace drift::render {

std::string object_name(const SceneInput& input, std::size_t i) {
  if (i < input.object_names.size() && !input.object_names[i].empty()) return input.object_names[i];
  return "object" + std::to_string(i + 1);
}

FrameMattes::FrameMattes(const TerrainScene& scene, const SceneInput& input) {
  material_.type = "CryptoMaterial";
  object_.type = "CryptoObject";
  material_.names = scene.coverage_names();
  coverage_count_ = static_cast<int>(material_.names.size());
  object_.names = {"terrain"};
  for (std::size_t i = 0; i < input.meshes.size(); ++i) {
    const std::string name = object_name(input, i);
    // Two objects of one name are one matte, as two rules of one name are.
    if (std::find(object_.names.begin(), object_.names.end(), name) == object_.names.end())
      object_.names.push_back(name);
    const std::string& preset = input.meshes[i].material;
    const std::string material = preset.empty() ? name : preset;
    auto it = std::find(material_.names.begin(), material_.names.end(), material);
    if (it == material_.names.end()) it = material_.names.insert(material_.names.end(), material);
    object_material_.push_back(static_cast<int>(it - material_.names.begin()));
  }
  material_.ranks = ranks_for(material_.names.size());
  object_.ranks = ranks_for(object_.names.size());
  for (const std::string& n : material_.names) material_ids_.push_back(cryptomatte_id(n));
  for (const std::string& n : object_.names) object_ids_.push_back(cryptomatte_id(n));
  // Object k's matte index: by its name (names may repeat).
  for (std::size_t i = 0; i < input.meshes.size(); ++i) {
    const auto it = std::find(object_.names.begin(), object_.names.end(), object_name(input, i));
    object_index_.push_back(static_cast<int>(it - object_.names.begin()));
  }
}

FrameMattes::Weights FrameMattes::weights() const {
  Weights w;
  w.material.assign(material_.names.size(), 0.0f);
  w.object.assign(object_.names.size(), 0.0f);
  return w;
}

void FrameMattes::add(Weights& w, int object, const Coverage& coverage) const {
  if (object < 0) {
    w.empty += 1.0f;
    return;
  }
  float covered = 0.0f;
  for (int c = 0; c < coverage_count_; ++c) {
    w.material[static_cast<std::size_t>(c)] += coverage[static_cast<std::size_t>(c)];
    covered += coverage[static_cast<std::size_t>(c)];
  }
  if (object == 0) {
    w.object[0] += 1.0f;
    return;
  }
  // An object: what its layers (snow) leave is its own material.
  const std::size_t k = static_cast<std::size_t>(object - 1);
  w.material[static_cast<std::size_t>(object_material_[k])] += std::max(0.0f, 1.0f - covered);
  w.object[static_cast<std::size_t>(object_index_[k])] += 1.0f;
}

void FrameMattes::write(const Weights& w, int samples, float* out) const {
  const float inv = 1.0f / static_cast<float>(samples);
  thread_local std::vector<float> scaled;
  scaled.resize(w.material.size());
  for (std::size_t i = 0; i < scaled.size(); ++i) scaled[i] = w.material[i] * inv;
  rank_coverage(material_, material_ids_, scaled.data(), w.empty * inv, out);
  scaled.resize(w.object.size());
  for (std::size_t i = 0; i < scaled.size(); ++i) scaled[i] = w.object[i] * inv;
  rank_coverage(object_, object_ids_, scaled.data(), w.empty * inv, out + 2 * material_.ranks);
}

}  // namespace drift::render
