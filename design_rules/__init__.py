"""Design rules over the parameters (and, when given, the built parts' mass properties and boxes) → Findings."""
from swiftfin.design_rules.findings import Finding, Severity, verdict
from swiftfin.design_rules.rules import (RULES, MassProperties, Rule, RuleContext, design_findings,
                                         mass_properties_from_json, run_rules)

__all__ = ["Finding", "Severity", "verdict", "RULES", "MassProperties", "Rule", "RuleContext",
           "run_rules", "design_findings", "mass_properties_from_json"]
