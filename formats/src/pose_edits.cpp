// The edits that write changed pose values back into a TUM or CSV document, shared by both
// writers: each row keeps the spans of its time, quaternion (w, x, y, z) and position fields.
#include "posefair/formats/format_detail.hpp"

namespace posefair::formats::detail {

void append_pose_edits(const Document& doc, const PoseSequence& old, const PoseSequence& poses,
                       std::vector<Edit>& edits) {
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const PoseSpans& row = doc.rows[k];
    if (!same_value(poses.time[k], old.time[k]))
      edits.push_back({row.time, format_number(poses.time[k])});
    const Quat& q = poses.orientation[k];
    if (!same_value(q, old.orientation[k])) {
      const double v[4] = {q.w(), q.x(), q.y(), q.z()};
      for (int i = 0; i < 4; ++i) edits.push_back({row.quat[i], format_number(v[i])});
    }
    if (poses.has_position())
      for (int i = 0; i < 3; ++i)
        if (!same_value(poses.position[k][i], old.position[k][i]))
          edits.push_back({row.pos[i], format_number(poses.position[k][i])});
  }
}

}  // namespace posefair::formats::detail
