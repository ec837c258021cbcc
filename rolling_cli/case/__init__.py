"""Case files: schema (:mod:`.schema`), validation (:mod:`.validate`), reading and
writing (:mod:`.io`)."""

from .io import case_to_dict, case_to_toml, load_case, with_overrides
from .schema import Case

__all__ = ["Case", "case_to_dict", "case_to_toml", "load_case", "with_overrides"]
