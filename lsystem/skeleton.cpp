#include "lsystem/skeleton.h"

namespace sprig::lsystem {

double Internode::length() const { return glm::length(end - start); }

DBox3 Skeleton::bounds() const {
  DBox3 b;
  for (const auto& in : internodes) {
    double r = std::max(in.baseRadius, in.tipRadius);
    b.extend(in.start - r);
    b.extend(in.start + r);
    b.extend(in.end - r);
    b.extend(in.end + r);
  }
  for (const auto& o : organs) {
    for (const auto& p : o.points) b.extend(p);
    if (o.kind != Organ::Kind::Polygon) {
      b.extend(o.position - o.radius);
      b.extend(o.position + o.radius);
    }
  }
  return b;
}

double Skeleton::totalLength() const {
  double s = 0;
  for (const auto& in : internodes) s += in.length();
  return s;
}

std::vector<std::vector<int32_t>> Skeleton::children() const {
  std::vector<std::vector<int32_t>> c(internodes.size());
  for (size_t i = 0; i < internodes.size(); ++i)
    if (internodes[i].parent >= 0) c[internodes[i].parent].push_back(static_cast<int32_t>(i));
  return c;
}

}  // namespace sprig::lsystem
