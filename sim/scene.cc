#include "sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "sim/intersect.h"

namespace pkslam::sim {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

}  // namespace

float Shape::bound_radius() const {
  switch (type) {
    case ShapeType::kCylinder:
      return std::hypot(half.x(), half.z());
    default:
      return half.norm();
  }
}

int Shape::num_faces() const {
  switch (type) {
    case ShapeType::kRoom:
    case ShapeType::kBox:
      return 6;
    case ShapeType::kCylinder:
      return 3;
    case ShapeType::kQuad:
      return 1;
  }
  return 0;
}

float SignedDistance(const Shape& shape, const Eigen::Vector3f& p_world) {
  const Eigen::Vector3f p = shape.world_from_local.transpose() * (p_world - shape.center);
  const Eigen::Vector3f& h = shape.half;
  switch (shape.type) {
    case ShapeType::kRoom: {
      const Eigen::Vector3f q = h - p.cwiseAbs();
      return q.minCoeff();
    }
    case ShapeType::kBox: {
      const Eigen::Vector3f q = p.cwiseAbs() - h;
      return q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f);
    }
    case ShapeType::kCylinder: {
      const Eigen::Vector2f q(std::hypot(p.x(), p.y()) - h.x(), std::abs(p.z()) - h.z());
      return q.cwiseMax(0.0f).norm() + std::min(q.maxCoeff(), 0.0f);
    }
    case ShapeType::kQuad: {
      const Eigen::Vector3f q(std::max(std::abs(p.x()) - h.x(), 0.0f),
                              std::max(std::abs(p.y()) - h.y(), 0.0f), p.z());
      return q.norm();
    }
  }
  return kInf;
}

bool Scene::Intersect(const Eigen::Vector3f& origin, const Eigen::Vector3f& dir, float t_max,
                      Hit* hit) const {
  float t = t_max;
  bool found = false;
  for (int i = 0; i < static_cast<int>(shapes.size()); ++i) {
    const Shape& s = shapes[i];
    const Eigen::Matrix3f rt = s.world_from_local.transpose();
    int face = 0;
    Eigen::Vector2f uv;
    Eigen::Vector3f n_local;
    if (IntersectLocal(s, rt * (origin - s.center), rt * dir, 1e-4f, &t, &face, &uv, &n_local)) {
      found = true;
      hit->t = t;
      hit->shape = i;
      hit->face = face;
      hit->uv = uv;
      hit->normal = s.world_from_local * n_local;
    }
  }
  return found;
}

float Scene::ObjectClearance(const Eigen::Vector3f& p) const {
  float best = kInf;
  for (const Shape& s : shapes) {
    if (s.type != ShapeType::kRoom) best = std::min(best, SignedDistance(s, p));
  }
  return best;
}

float Scene::RoomClearance(const Eigen::Vector3f& p) const {
  const Shape* room = Room();
  return room ? SignedDistance(*room, p) : kInf;
}

const Shape* Scene::Room() const {
  for (const Shape& s : shapes) {
    if (s.type == ShapeType::kRoom) return &s;
  }
  return nullptr;
}

Scene::FaceFrame Scene::Face(const Shape& shape, int face) {
  const Eigen::Vector3f& h = shape.half;
  FaceFrame f;
  switch (shape.type) {
    case ShapeType::kRoom:
    case ShapeType::kBox: {
      const int axis = face / 2;
      const float sign = (face % 2 == 1) ? 1.0f : -1.0f;
      const int a = axis == 0 ? 1 : 0;
      const int b = axis == 2 ? 1 : 2;
      f.origin = Eigen::Vector3f::Zero();
      f.origin[axis] = sign * h[axis];
      f.origin[a] = -h[a];
      f.origin[b] = -h[b];
      f.axis_u = Eigen::Vector3f::Unit(a);
      f.axis_v = Eigen::Vector3f::Unit(b);
      f.normal = Eigen::Vector3f::Zero();
      f.normal[axis] = shape.type == ShapeType::kRoom ? -sign : sign;
      f.size = Eigen::Vector2f(2.0f * h[a], 2.0f * h[b]);
      return f;
    }
    case ShapeType::kCylinder:
      // Side handled by callers through (angle*r, z); caps as boxes' z faces.
      f.origin = Eigen::Vector3f(-h.x(), -h.x(), face == 1 ? -h.z() : h.z());
      f.axis_u = Eigen::Vector3f::UnitX();
      f.axis_v = Eigen::Vector3f::UnitY();
      f.normal = Eigen::Vector3f(0.0f, 0.0f, face == 1 ? -1.0f : 1.0f);
      f.size = face == 0 ? Eigen::Vector2f(2.0f * std::numbers::pi_v<float> * h.x(), 2.0f * h.z())
                         : Eigen::Vector2f(2.0f * h.x(), 2.0f * h.x());
      return f;
    case ShapeType::kQuad:
      f.origin = Eigen::Vector3f(-h.x(), -h.y(), 0.0f);
      f.axis_u = Eigen::Vector3f::UnitX();
      f.axis_v = Eigen::Vector3f::UnitY();
      f.normal = Eigen::Vector3f::UnitZ();
      f.size = Eigen::Vector2f(2.0f * h.x(), 2.0f * h.y());
      return f;
  }
  return f;
}

bool Scene::SurfacePoint(const Shape& shape, int face, const Eigen::Vector2f& uv,
                         Eigen::Vector3f* p_world, Eigen::Vector3f* n_world) {
  Eigen::Vector3f p_local;
  Eigen::Vector3f n_local;
  if (shape.type == ShapeType::kCylinder && face == 0) {
    const float r = shape.half.x();
    const float angle = uv.x() / r - std::numbers::pi_v<float>;
    n_local = Eigen::Vector3f(std::cos(angle), std::sin(angle), 0.0f);
    p_local = Eigen::Vector3f(r * n_local.x(), r * n_local.y(), uv.y() - shape.half.z());
  } else {
    const FaceFrame frame = Face(shape, face);
    p_local = frame.origin + uv.x() * frame.axis_u + uv.y() * frame.axis_v;
    n_local = frame.normal;
    if (shape.type == ShapeType::kCylinder &&
        p_local.head<2>().squaredNorm() > shape.half.x() * shape.half.x()) {
      return false;  // cap samples outside the disc
    }
  }
  *p_world = shape.center + shape.world_from_local * p_local;
  *n_world = shape.world_from_local * n_local;
  return true;
}

}  // namespace pkslam::sim
