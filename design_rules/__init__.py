"""Design rules over the parameters (and, when given, the built parts' mass properties and boxes) → Findings."""
from design_rules.findings import Finding, Severity, verdict
from design_rules.rules import RULES, MassProperties, Rule, RuleContext, run_rules

__all__ = ["Finding", "Severity", "verdict", "RULES", "MassProperties", "Rule", "RuleContext",
           "run_rules"]
