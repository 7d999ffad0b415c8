#include "sim/scene.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace pkslam::sim {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Face (u, v) coordinates in metres for a box-like face (axis a, sign s): the two other
// axes, measured from the face's corner.
Eigen::Vector2f BoxUv(const Eigen::Vector3f& p, const Eigen::Vector3f& half, int axis) {
  const int a = axis == 0 ? 1 : 0;
  const int b = axis == 2 ? 1 : 2;
  return {p[a] + half[a], p[b] + half[b]};
}

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

bool IntersectLocal(const Shape& shape, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                    float t_min, float* t, int* face, Eigen::Vector2f* uv,
                    Eigen::Vector3f* normal_local) {
  const Eigen::Vector3f& h = shape.half;
  switch (shape.type) {
    case ShapeType::kRoom: {
      // Inside-out box: the exit distance.
      float best = kInf;
      int axis = 0;
      for (int i = 0; i < 3; ++i) {
        if (d[i] == 0.0f) continue;
        const float ti = ((d[i] > 0.0f ? h[i] : -h[i]) - o[i]) / d[i];
        if (ti < best) {
          best = ti;
          axis = i;
        }
      }
      if (!(best > t_min && best < *t)) return false;
      *t = best;
      const bool positive = d[axis] > 0.0f;
      *face = 2 * axis + (positive ? 1 : 0);
      const Eigen::Vector3f p = o + best * d;
      *uv = BoxUv(p, h, axis);
      *normal_local = Eigen::Vector3f::Zero();
      (*normal_local)[axis] = positive ? -1.0f : 1.0f;
      return true;
    }
    case ShapeType::kBox: {
      float t_near = -kInf;
      float t_far = kInf;
      int axis = 0;
      for (int i = 0; i < 3; ++i) {
        if (d[i] == 0.0f) {
          if (std::abs(o[i]) > h[i]) return false;
          continue;
        }
        const float inv = 1.0f / d[i];
        float t0 = (-h[i] - o[i]) * inv;
        float t1 = (h[i] - o[i]) * inv;
        if (t0 > t1) std::swap(t0, t1);
        if (t0 > t_near) {
          t_near = t0;
          axis = i;
        }
        t_far = std::min(t_far, t1);
      }
      if (t_near > t_far || !(t_near > t_min && t_near < *t)) return false;
      *t = t_near;
      const bool from_negative = d[axis] > 0.0f;  // entering through the -axis face
      *face = 2 * axis + (from_negative ? 0 : 1);
      *uv = BoxUv(o + t_near * d, h, axis);
      *normal_local = Eigen::Vector3f::Zero();
      (*normal_local)[axis] = from_negative ? -1.0f : 1.0f;
      return true;
    }
    case ShapeType::kCylinder: {
      const float r = h.x();
      bool hit = false;
      // Side: (ox + t dx)^2 + (oy + t dy)^2 = r^2, entering root.
      const float a = d.x() * d.x() + d.y() * d.y();
      if (a > 0.0f) {
        const float b = o.x() * d.x() + o.y() * d.y();
        const float c = o.x() * o.x() + o.y() * o.y() - r * r;
        const float disc = b * b - a * c;
        if (disc >= 0.0f) {
          const float ts = (-b - std::sqrt(disc)) / a;
          const float z = o.z() + ts * d.z();
          if (ts > t_min && ts < *t && std::abs(z) <= h.z()) {
            *t = ts;
            *face = 0;
            const float x = o.x() + ts * d.x();
            const float y = o.y() + ts * d.y();
            const float angle = std::atan2(y, x) + std::numbers::pi_v<float>;
            *uv = Eigen::Vector2f(angle * r, z + h.z());
            *normal_local = Eigen::Vector3f(x / r, y / r, 0.0f);
            hit = true;
          }
        }
      }
      // Caps.
      if (d.z() != 0.0f) {
        const float cap_z = d.z() > 0.0f ? -h.z() : h.z();
        const float tc = (cap_z - o.z()) / d.z();
        const float x = o.x() + tc * d.x();
        const float y = o.y() + tc * d.y();
        if (tc > t_min && tc < *t && x * x + y * y <= r * r) {
          *t = tc;
          *face = d.z() > 0.0f ? 1 : 2;
          *uv = Eigen::Vector2f(x + r, y + r);
          *normal_local = Eigen::Vector3f(0.0f, 0.0f, d.z() > 0.0f ? -1.0f : 1.0f);
          hit = true;
        }
      }
      return hit;
    }
    case ShapeType::kQuad: {
      if (d.z() == 0.0f) return false;
      const float tq = -o.z() / d.z();
      if (!(tq > t_min && tq < *t)) return false;
      const float x = o.x() + tq * d.x();
      const float y = o.y() + tq * d.y();
      if (std::abs(x) > h.x() || std::abs(y) > h.y()) return false;
      *t = tq;
      *face = 0;
      *uv = Eigen::Vector2f(x + h.x(), y + h.y());
      *normal_local = Eigen::Vector3f(0.0f, 0.0f, d.z() > 0.0f ? -1.0f : 1.0f);
      return true;
    }
  }
  return false;
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

}  // namespace pkslam::sim
