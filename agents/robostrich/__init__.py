"""The arm's glue between robostrich_suite and the generic agent: domains, training defaults and
command, the lookup baseline, evaluations, transfer to the quadruped and the application tools."""
