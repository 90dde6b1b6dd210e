#include "synth_scene.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtx/quaternion.hpp>

#include "mrgi/image.h"
#include "mrgi/reference/shapes.h"
#include "shared/mrgi_shared.h"

namespace mrgi::reference {

namespace {

// glTF metallic-roughness + KHR_materials_transmission/ior to the reference materials.
RefMaterial from_gltf(const Material& m, int texture_offset) {
  RefMaterial r;
  r.base_color = glm::clamp(glm::vec3(m.base_color_factor), 0.0f, 1.0f);
  r.texture = m.base_color_texture >= 0 ? m.base_color_texture + texture_offset : -1;
  r.roughness = glm::clamp(m.roughness, 0.0f, 1.0f);
  r.metallic = glm::clamp(m.metallic, 0.0f, 1.0f);
  r.ior = m.ior;
  // An emissive texture is not rendered here: the reference's emitters have one radiance per
  // mesh (sampled for next-event estimation by area), so a textured one emits its factor.
  r.emission = glm::max(m.emissive, glm::vec3(0.0f));
  if (m.transmission >= 0.5f) r.type = MaterialType::Glass;
  else if (r.metallic >= 0.99f && r.roughness <= 0.02f) r.type = MaterialType::Mirror;
  else if (r.metallic <= 0.0f && r.roughness >= 1.0f) r.type = MaterialType::Diffuse;
  else r.type = MaterialType::Glossy;
  return r;
}

ImageRGBF linear_texture(const ImageRGBA8& srgb) {
  ImageRGBF out(srgb.width, srgb.height);
  for (size_t i = 0; i < srgb.pixel_count(); ++i)
    for (int c = 0; c < 3; ++c) out.data[3 * i + c] = shader::srgb_decode1(srgb.data[4 * i + c] / 255.0f);
  return out;
}

// Appends a glTF model's primitives, materials and textures to `scene`.
void append_model(const Model& model, bool is_virtual, const std::optional<RefMaterial>& override_material,
                  RefScene& scene, std::vector<RefMesh>* meshes_out) {
  const int texture_offset = int(scene.textures.size());
  const int material_offset = int(scene.materials.size());
  if (override_material) {
    scene.materials.push_back(*override_material);
  } else {
    for (const Texture& t : model.textures) scene.textures.push_back(linear_texture(t.image));
    for (const Material& m : model.materials) scene.materials.push_back(from_gltf(m, texture_offset));
    scene.materials.push_back(from_gltf(Material{}, texture_offset));  // glTF default material
  }
  const int default_material = int(scene.materials.size()) - 1;
  for (const MeshPrimitive& p : model.primitives) {
    RefMesh mesh;
    mesh.positions = p.positions;
    mesh.normals = p.normals;
    mesh.uvs = p.uvs;
    mesh.indices = p.indices;
    mesh.is_virtual = is_virtual;
    mesh.material = override_material || p.material < 0 ? default_material : material_offset + p.material;
    meshes_out->push_back(std::move(mesh));
  }
}

glm::mat4 placement_matrix(const glm::dvec3& position, const glm::dquat& rotation, double scale) {
  return glm::mat4(glm::translate(glm::dmat4(1.0), position) * glm::mat4_cast(rotation) *
                   glm::scale(glm::dmat4(1.0), glm::dvec3(scale)));
}

// Rotation taking +y to unit vector d.
glm::dquat rotation_from_y(const glm::dvec3& d) {
  const glm::dvec3 y(0.0, 1.0, 0.0);
  const double c = glm::dot(y, d);
  if (c < -0.999999) return glm::angleAxis(3.14159265358979323846, glm::dvec3(1.0, 0.0, 0.0));
  return glm::rotation(y, d);
}

}  // namespace

Expected<SynthScene> SynthScene::load(const SceneDescription& d) {
  SynthScene s;
  s.description_ = &d;
  RefScene& scene = s.real_;
  for (size_t i = 0; i < d.real_objects.size(); ++i) {
    const RealObjectDesc& o = d.real_objects[i];
    const glm::mat4 m = placement_matrix(o.position, o.rotation, o.scale);
    if (o.shape == ShapeKind::Gltf) {
      Placement p;
      p.position = glm::vec3(o.position);
      p.rotation = glm::quat(o.rotation);
      p.scale = glm::vec3(float(o.scale));
      auto model = load_gltf(o.gltf, p);
      if (!model) return fail(model.error().kind, d.path + ": real_objects[" + std::to_string(i) + "]: " + model.error().message);
      append_model(*model, false, o.material, scene, &scene.meshes);
      continue;
    }
    RefMesh mesh = o.shape == ShapeKind::Plane  ? make_plane(glm::vec2(o.size.x, o.size.y), m)
                   : o.shape == ShapeKind::Box ? make_box(glm::vec3(o.size), m)
                                               : make_sphere(float(o.radius), 64, m);
    mesh.material = int(scene.materials.size());
    scene.materials.push_back(*o.material);
    scene.meshes.push_back(std::move(mesh));
  }
  for (const LampDesc& l : d.lights) {
    const glm::vec3 power = glm::vec3(l.color * l.intensity);
    if (l.type == LampKind::Area) {
      const glm::mat4 m = glm::mat4(glm::translate(glm::dmat4(1.0), l.position) * glm::mat4_cast(rotation_from_y(l.direction)));
      RefMesh quad = make_plane(glm::vec2(l.size), m);
      RefMaterial emitter;
      emitter.base_color = glm::vec3(0.0f);
      emitter.emission = power;
      quad.material = int(scene.materials.size());
      quad.is_virtual = !l.real;
      scene.materials.push_back(emitter);
      scene.meshes.push_back(std::move(quad));
      continue;
    }
    RefLight r;
    r.type = l.type == LampKind::Point ? RefLightType::Point
             : l.type == LampKind::Spot ? RefLightType::Spot
                                        : RefLightType::Directional;
    r.is_virtual = !l.real;
    r.position = glm::vec3(l.position);
    r.direction = glm::vec3(l.direction);
    r.intensity = power;
    const double deg = 3.14159265358979323846 / 180.0;
    r.cos_inner = float(std::cos(l.inner_angle_deg * deg));
    r.cos_outer = float(std::cos(l.outer_angle_deg * deg));
    scene.lights.push_back(r);
  }
  if (d.environment.present) {
    if (d.environment.sky) {
      scene.environment.image = render_sky(*d.environment.sky);
    } else {
      auto img = load_hdr_image(d.environment.image);
      if (!img) return fail(img.error().kind, d.path + ": environment.image: " + img.error().message);
      scene.environment.image = std::move(*img);
    }
    scene.environment.intensity = float(d.environment.intensity);
    scene.environment.rotation = glm::mat3(glm::mat3_cast(glm::quat(d.environment.rotation)));
  }
  for (size_t i = 0; i < d.virtual_objects.size(); ++i) {
    auto model = load_gltf(d.virtual_objects[i].gltf, Placement{});
    if (!model)
      return fail(model.error().kind, d.path + ": virtual_objects[" + std::to_string(i) + "]: " + model.error().message);
    const size_t before = s.virtual_local_.size();
    append_model(*model, true, std::nullopt, scene, &s.virtual_local_);
    s.virtual_owner_.resize(s.virtual_local_.size(), i);
    if (s.virtual_local_.size() == before)
      return fail(ErrorKind::BadInput, d.path + ": virtual_objects[" + std::to_string(i) + "]: '" +
                                           d.virtual_objects[i].gltf + "' has no triangles");
  }
  return s;
}

Placement SynthScene::virtual_placement(size_t i, double t) const {
  const VirtualObjectMotionDesc& v = description_->virtual_objects[i];
  Placement p;
  p.position = glm::vec3(v.position + v.velocity * t);
  const double rate = glm::length(v.angular_velocity_deg);
  glm::dquat spin(1.0, 0.0, 0.0, 0.0);
  if (rate > 0.0) spin = glm::angleAxis(glm::radians(rate * t), v.angular_velocity_deg / rate);
  p.rotation = glm::quat(glm::normalize(spin * v.rotation));
  p.scale = glm::vec3(float(v.scale));
  return p;
}

RefScene SynthScene::at_time(double t) const {
  RefScene scene = real_;
  std::vector<glm::mat4> matrices;
  for (size_t i = 0; i < description_->virtual_objects.size(); ++i) matrices.push_back(virtual_placement(i, t).matrix());
  for (size_t k = 0; k < virtual_local_.size(); ++k) {
    RefMesh mesh = virtual_local_[k];
    const glm::mat4& m = matrices[virtual_owner_[k]];
    const glm::mat3 nm = glm::transpose(glm::inverse(glm::mat3(m)));
    for (glm::vec3& p : mesh.positions) p = glm::vec3(m * glm::vec4(p, 1.0f));
    for (glm::vec3& n : mesh.normals) n = glm::normalize(nm * n);
    scene.meshes.push_back(std::move(mesh));
  }
  return scene;
}

}  // namespace mrgi::reference
