"""What the thesis itself says, as data: its tables and parameters (:mod:`.numbers`) and its
comparative claims (:mod:`.claims`). Nothing here measures anything."""
