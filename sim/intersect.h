// Ray/shape intersection in a shape's local frame (inline: the renderer's inner loop).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "sim/scene.h"

namespace pkslam::sim {
namespace intersect_detail {

constexpr float kInf = std::numeric_limits<float>::infinity();

// Face (u, v) coordinates in metres for a box-like face (axis a, sign s): the two other
// axes, measured from the face's corner.
inline Eigen::Vector2f BoxUv(const Eigen::Vector3f& p, const Eigen::Vector3f& half, int axis) {
  const int a = axis == 0 ? 1 : 0;
  const int b = axis == 2 ? 1 : 2;
  return {p[a] + half[a], p[b] + half[b]};
}

}  // namespace intersect_detail

// Ray/shape test in the shape's local frame. o/d are local; d need not be unit (t is in
// units of d). Returns false on a miss or a hit not in (t_min, *t); on a hit sets *t and the
// face. The surface there (SurfaceAtLocal) is left for the caller to compute once it knows the
// nearest hit: the renderer tests several shapes per ray, and a cylinder's (u, v) costs an
// atan2.
inline bool HitLocal(const Shape& shape, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                     float t_min, float* t, int* face) {
  const Eigen::Vector3f& h = shape.half;
  switch (shape.type) {
    case ShapeType::kRoom: {
      // Inside-out box: the exit distance.
      float best = intersect_detail::kInf;
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
      *face = 2 * axis + (d[axis] > 0.0f ? 1 : 0);
      return true;
    }
    case ShapeType::kBox: {
      float t_near = -intersect_detail::kInf;
      float t_far = intersect_detail::kInf;
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
      *face = 2 * axis + (d[axis] > 0.0f ? 0 : 1);  // 0: entering through the -axis face
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
      return true;
    }
  }
  return false;
}

// The surface where HitLocal's ray (o, d) meets the shape at t on `face`: its (u, v) in metres
// and the local normal facing the ray. The same arithmetic as the hit test, so the point is
// the one it found.
inline void SurfaceAtLocal(const Shape& shape, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                           float t, int face, Eigen::Vector2f* uv, Eigen::Vector3f* normal_local) {
  const Eigen::Vector3f& h = shape.half;
  switch (shape.type) {
    case ShapeType::kRoom:
    case ShapeType::kBox: {
      const int axis = face / 2;
      *uv = intersect_detail::BoxUv(o + t * d, h, axis);
      *normal_local = Eigen::Vector3f::Zero();
      // Odd faces are on the axis' positive side. Room (seen from inside): its normal points
      // back in; box: out.
      const bool positive_side = face % 2 == 1;
      const bool inward = shape.type == ShapeType::kRoom;
      (*normal_local)[axis] = positive_side == inward ? -1.0f : 1.0f;
      return;
    }
    case ShapeType::kCylinder: {
      const float r = h.x();
      const float x = o.x() + t * d.x();
      const float y = o.y() + t * d.y();
      if (face == 0) {
        const float z = o.z() + t * d.z();
        const float angle = std::atan2(y, x) + std::numbers::pi_v<float>;
        *uv = Eigen::Vector2f(angle * r, z + h.z());
        *normal_local = Eigen::Vector3f(x / r, y / r, 0.0f);
      } else {
        *uv = Eigen::Vector2f(x + r, y + r);
        *normal_local = Eigen::Vector3f(0.0f, 0.0f, d.z() > 0.0f ? -1.0f : 1.0f);
      }
      return;
    }
    case ShapeType::kQuad: {
      const float x = o.x() + t * d.x();
      const float y = o.y() + t * d.y();
      *uv = Eigen::Vector2f(x + h.x(), y + h.y());
      *normal_local = Eigen::Vector3f(0.0f, 0.0f, d.z() > 0.0f ? -1.0f : 1.0f);
      return;
    }
  }
  *uv = Eigen::Vector2f::Zero();  // not reached (every shape type returns above)
  *normal_local = Eigen::Vector3f::Zero();
}

// HitLocal and, on a hit, SurfaceAtLocal.
inline bool IntersectLocal(const Shape& shape, const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                           float t_min, float* t, int* face, Eigen::Vector2f* uv,
                           Eigen::Vector3f* normal_local) {
  if (!HitLocal(shape, o, d, t_min, t, face)) return false;
  SurfaceAtLocal(shape, o, d, *t, *face, uv, normal_local);
  return true;
}

}  // namespace pkslam::sim
