#include "model/types.h"

namespace omnical {

const char* StatusName(ProjectionStatus status) {
  switch (status) {
    case ProjectionStatus::kOk: return "ok";
    case ProjectionStatus::kOutsideMirror: return "outside_mirror";
    case ProjectionStatus::kBehindMirror: return "behind_mirror";
    case ProjectionStatus::kOccludedByCamera: return "occluded_by_camera";
    case ProjectionStatus::kOutsideImage: return "outside_image";
    case ProjectionStatus::kMissesMirror: return "misses_mirror";
    case ProjectionStatus::kNoSolution: return "no_solution";
    case ProjectionStatus::kInvalidInput: return "invalid_input";
  }
  return "unknown";
}

}  // namespace omnical
