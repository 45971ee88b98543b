#include "terrain/products.h"

#include "terrain/error.h"
#include "terrain/mesh_io.h"

namespace drift::terrain::products {

void require_form(const Mesh& mesh, const AttributedMeshForm& form,
                  const std::filesystem::path& file) {
  for (const char* name : form.attributes) {
    const std::vector<float>* values = mesh.attribute(name);
    if (values && values->size() == mesh.vertex_count()) continue;
    const std::string problem = values ? "have " + std::to_string(values->size()) + " '" + name +
                                             "' values for " + std::to_string(mesh.vertex_count()) +
                                             " vertices"
                                       : std::string("have no '") + name + "' attribute";
    throw Error(std::string("'").append(file.string()) + "' is not " + form.name +
                ": its vertices " + problem + " (write it with " + form.written_by + ")");
  }
}

std::vector<Mesh> split_objects(const Mesh& mesh, const AttributedMeshForm& form,
                                const std::filesystem::path& file) {
  require_form(mesh, form, file);
  return split_by_attribute(mesh, kObjectIndex);
}

}  // namespace drift::terrain::products
