// ICT-FaceKit's morphable head (USC ICT, MIT licence; github.com/ICT-VGL/ICT-FaceKit), read from
// the one-file model that scripts/convert_ict_facekit.py writes (format: models/ict-facekit/README.md).
//
// Frame and units of every mesh here: the head frame of the source, centimetres, +y up, the face
// looks down +z, the subject's left is +x (iBUG landmark 0, the subject's right jaw, has x < 0). The
// neutral head spans about [-12.4, 12.4] x [-19.3, 14.5] x [-9.2, 13.1] (neck cut at the bottom).
// Triangles wind counter-clockwise seen from outside.
//
// The mesh is linear in the coefficients:
//   mesh = neutral + sum_i identity[i] * identity_mode_i + sum_e expression[e] * expression_delta_e
// Identity modes are PCA modes already scaled by their standard deviations, so identity
// coefficients are ~N(0, 1); expression weights are ARKit-style, 0 (rest) to 1 (full).
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "icef/core/status.h"
#include "icef/math/types.h"

namespace icef::face {

class IctModel {
 public:
  static constexpr int kNumLandmarks = 68;  // iBUG / Multi-PIE 68-point markup

  // Reads the model file. Every failure is one line naming the file and what is wrong.
  static Result<IctModel> Load(const std::filesystem::path& path);
  // $ICEF_FACE_MODEL when set and non-empty, else the repository's models/ict-facekit/ict_facekit.bin.
  static std::filesystem::path DefaultPath();
  // The model at DefaultPath(), read once per process (per path) and shared; thread-safe.
  static Result<std::shared_ptr<const IctModel>> LoadDefault();

  int num_vertices() const { return static_cast<int>(neutral_.size()); }
  int num_identities() const { return num_identities_; }
  int num_expressions() const { return static_cast<int>(expression_names_.size()); }
  const std::string& source_commit() const { return source_commit_; }  // ICT-FaceKit git commit
  const std::filesystem::path& path() const { return path_; }

  // The 53 expression names in ICT's spelling of ARKit's names (mouthSmile_L for mouthSmileLeft).
  const std::vector<std::string>& expression_names() const { return expression_names_; }
  // The index of one expression, by ICT's spelling (mouthSmile_L) or ARKit's (mouthSmileLeft),
  // ignoring case (Live Link Face writes MouthSmileLeft); -1 when unknown, and -1 for ARKit's
  // browInnerUp and cheekPuff, which the model splits into _L/_R (see ExpressionTargets).
  int ExpressionIndex(std::string_view name) const;
  // The indices a name drives: one, or both halves of a split pair (browInnerUp -> browInnerUp_L,
  // browInnerUp_R); empty when unknown.
  std::vector<int> ExpressionTargets(std::string_view name) const;
  // The ARKit names the model covers, in the order of its expressions (mouthSmile_L ->
  // mouthSmileLeft; a split pair once, by its unsided name): 51 for ICT-FaceKit (ARKit's 52 less
  // tongueOut). ExpressionTargets maps each back.
  std::vector<std::string> ArkitNames() const;

  // Mesh at the coefficients: [num_vertices] positions. A span shorter than the count leaves the
  // remaining coefficients at 0 (empty = all 0); a longer one fails an ICEF_CHECK. Coefficients
  // that are exactly 0 add nothing, so Mesh({}, {}) is the neutral bit for bit.
  std::vector<Vec3f> Mesh(std::span<const float> identity, std::span<const float> expression) const;
  const std::vector<Vec3f>& neutral() const { return neutral_; }
  // One mode's per-vertex displacements: [num_vertices].
  std::span<const Vec3f> IdentityMode(int i) const;
  std::span<const Vec3f> ExpressionDelta(int e) const;

  // Faces: the source's quads fan-split (a, b, c, d) -> (a, b, c), (a, c, d), in source order.
  const std::vector<std::array<uint32_t, 3>>& triangles() const { return triangles_; }
  // Texture coordinates are per corner (the source has UV seams): triangle_uvs()[t][k] indexes
  // uvs() for corner k of triangle t. OBJ convention: v = 0 at the bottom of the texture.
  const std::vector<Vec2f>& uvs() const { return uvs_; }
  const std::vector<std::array<uint32_t, 3>>& triangle_uvs() const { return triangle_uvs_; }

  // The 68 landmark vertex indices (-1 where the model has none) and their positions on a mesh of
  // num_vertices() (NaN for a missing one).
  const std::array<int32_t, kNumLandmarks>& landmark_vertices() const { return landmarks_; }
  std::vector<Vec3f> Landmarks(const std::vector<Vec3f>& mesh) const;

  // Parts (face, head_neck, mouth_socket, eye_socket_left, ..., gums_tongue, teeth, sclera_left,
  // iris_left, ...): a name table and one label per vertex indexing it.
  const std::vector<std::string>& part_names() const { return part_names_; }
  const std::vector<uint8_t>& part_labels() const { return part_labels_; }
  int PartIndex(std::string_view name) const;  // -1 when unknown

  // Named vertex lists of the source (fitting_verts, rigid_verts, lap_rigid_verts, jawline_left,
  // jawline_right(_extended), narrow_face_area); an empty span when unknown.
  std::vector<std::string> VertexSetNames() const;
  std::span<const uint32_t> VertexSet(std::string_view name) const;

  std::string ToString() const;

 private:
  IctModel() = default;
  friend class IctModelReader;

  std::filesystem::path path_;
  std::string source_commit_;
  int num_identities_ = 0;
  std::vector<Vec3f> neutral_;
  std::vector<Vec3f> identity_modes_;     // [num_identities][num_vertices]
  std::vector<Vec3f> expression_deltas_;  // [num_expressions][num_vertices]
  std::vector<std::array<uint32_t, 3>> triangles_, triangle_uvs_;
  std::vector<Vec2f> uvs_;
  std::vector<std::string> expression_names_, part_names_;
  std::vector<uint8_t> part_labels_;
  std::array<int32_t, kNumLandmarks> landmarks_{};
  std::vector<std::pair<std::string, std::vector<uint32_t>>> vertex_sets_;
};

// Parses "jawOpen=0.8,mouthSmileLeft=0.5" into num_expressions() weights (unnamed ones 0). Names
// in ARKit's or ICT's spelling (ExpressionIndex); ARKit's browInnerUp and cheekPuff set both
// halves. Values must be finite numbers. An unknown name, a name given twice, or a malformed item
// is an error naming the item and listing the valid names.
Result<std::vector<float>> ParseArkitExpression(const IctModel& model, std::string_view text);

}  // namespace icef::face
