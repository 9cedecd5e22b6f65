"""Detection on a stream of strains: contact (``contact``), buckling (``buckling``) and the
load's plateau (``plateau``)."""
