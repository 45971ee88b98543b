#include "terrain/marks/marks_parameters.h"

namespace drift::marks {

using terrain::Ends;

const std::vector<MarksParameter>& marks_parameters() {
  static const std::vector<MarksParameter> table = {
      {"step", "", 0, 3600, Ends::OpenLow, false, "s", "simulated time per step",
       DRIFT_PARAMETER_FIELD(MarksOptions, step), "step"},
      {"memory_steps", "--memory-steps", 0, 1000000, Ends::Closed, true, "steps",
       "steps a cell that slid, or that an object held, keeps relaxing after it last moved or "
       "was let go (paper 000, 3.5)",
       DRIFT_PARAMETER_FIELD(MarksOptions, memory_steps)},
      {"erosion_passes", "--erosion-passes", 1, 100000, Ends::Closed, true, "",
       "most relaxation passes per erosion (one a step, and one a sub-step before the last)",
       DRIFT_PARAMETER_FIELD(MarksOptions, erosion_passes)},
      {"margin", "--margin", 2, 1000, Ends::Closed, true, "cells",
       "free cells kept around an object's footprint for its rim",
       DRIFT_PARAMETER_FIELD(MarksOptions, margin)},
  };
  return table;
}

}  // namespace drift::marks
