//! modelDescription.xml: the committed files are the generator's output, and every variable
//! table obeys the FMI 2.0 rules the generator relies on.

use boomsim::fmu::{Causality, Kind, Variable};
use boomsim::fmu::Version;
use boomsim::models;
use boomsim::units::unit;
use std::path::Path;

#[test]
fn committed_model_descriptions_are_current() {
    for (version, dir) in [(Version::Fmi2, "modelDescription"), (Version::Fmi3, "modelDescription/fmi3")] {
        for f in boomsim_tools::pack::all().into_iter().filter(|f| f.has(version)) {
            let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/..")).join(format!("{dir}/{}.xml", f.identifier));
            let committed = std::fs::read_to_string(&path).unwrap_or_default();
            let current = (f.model_description)(version);
            assert!(committed == current, "{} is out of date: run `boomsim xml`", path.display());
        }
    }
}

/// FMI 2.0 section 2.2.7: unique value references, declared units, start within range, and
/// output dependencies on inputs only; FMI 3.0, 2.4.8: a clocked output's also on the
/// discrete-time states (the clocked variables with a previous value), and on its Clock (an
/// input), which must be listed.
fn check_table(id: &str, vars: &[Variable]) {
    for (i, v) in vars.iter().enumerate() {
        assert!(vars[i + 1..].iter().all(|w| w.vr != v.vr && w.name != v.name), "{id}: {} is not unique", v.name);
        if let Kind::Real { start, unit: u, display_unit, min, max } = v.kind {
            let declared = unit(u).unwrap_or_else(|| panic!("{id}: unit {u} of {} is not declared", v.name));
            assert!(display_unit.is_empty() || declared.display.iter().any(|d| d.name == display_unit));
            assert!(min <= max, "{id}: {} has min > max", v.name);
            if v.has_start() {
                assert!((min..=max).contains(&start), "{id}: start of {} is outside [min, max]", v.name);
            }
        }
        for dep in v.depends_on {
            let d = vars.iter().find(|w| w.vr == *dep).expect("dependency exists");
            let discrete_state = v.clocked && d.clocked && d.previous.is_some();
            assert!(d.causality == Causality::Input || discrete_state, "{id}: {} depends on non-input {}", v.name, d.name);
        }
        if v.clocked && !v.depends_on.is_empty() {
            let clock = vars.iter().find(|w| matches!(w.kind, Kind::Clock { .. })).expect("a clocked variable's Clock");
            assert!(v.depends_on.contains(&clock.vr), "{id}: {} does not list its Clock {}", v.name, clock.name);
        }
    }
}

#[test]
fn variable_tables_obey_fmi_rules() {
    use boomsim::fmu::Model;
    check_table("PressureFeedbackController", models::PressureFeedbackController::VARIABLES);
    check_table("ClockedPressureFeedbackController", models::ClockedPressureFeedbackController::VARIABLES);
    check_table("HydraulicBoom", models::HydraulicBoom::VARIABLES);
}

/// The page inside the FMU states the default boom (it once said "the rigid boom with eight
/// states" while the default was the flexible arm): it follows `boom.flexible`'s start value.
#[test]
fn the_documentation_names_the_default_boom() {
    use boomsim::fmu::Model;
    use boomsim::models::HydraulicBoom;
    let flexible = HydraulicBoom::VARIABLES.iter().find(|v| v.name == "boom.flexible").unwrap();
    let Kind::Boolean { start } = flexible.kind else { panic!("boom.flexible is a Boolean") };
    let doc = boomsim_tools::pack::documentation::<HydraulicBoom>(Version::Fmi2, &boomsim_tools::platform::PLATFORMS);
    let says = if start { "by default the lumped flexible" } else { "by default the rigid" };
    assert!(doc.contains(says), "the documentation does not say \"{says}\"");
    assert!(!doc.contains("eight states"));
}

/// One project version in every FMU (the workspace version; `scripts/bump-version` sets it).
#[test]
fn every_fmu_carries_the_project_version() {
    for f in boomsim_tools::pack::all() {
        let fmi = if f.has(Version::Fmi2) { Version::Fmi2 } else { Version::Fmi3 };
        let xml = (f.model_description)(fmi);
        let version = format!("version=\"{}\"", env!("CARGO_PKG_VERSION"));
        assert!(xml.contains(&version), "{} lacks {version}", f.identifier);
        assert!((f.documentation)(fmi, &[]).contains(&format!(
            "{} {}",
            f.identifier,
            env!("CARGO_PKG_VERSION")
        )));
    }
}

/// The page's facts come from the model and the pack: the GUID of the XML, the platforms packed,
/// and start values also in their display unit (the controller's Q_rated: 25 l/min of the
/// thesis' valve, not only 0.0004166666666666667 m3/s).
#[test]
fn the_page_states_generated_facts() {
    use boomsim::fmu::{guid::guid, Model};
    use boomsim::models::PressureFeedbackController as Pfc;
    let platforms = &boomsim_tools::platform::PLATFORMS[..2];
    let page = boomsim_tools::pack::documentation::<Pfc>(Version::Fmi2, platforms);
    assert!(page.contains(&guid::<Pfc>()));
    assert!(page.contains("<td>linux64, win64</td>"), "platforms");
    assert!(page.contains("(25 l/min)"), "Q_rated in l/min");
    let i = Pfc::INFO;
    assert!(page.contains(&format!("{} to {} s", i.start_time, i.stop_time)));
    // The Model Exchange tolerance the model needs: any for the controller's linear filter, the
    // circuit's 1e-6 for HydraulicBoom (docs/interfaces.md's tolerance table), the one its warning names.
    assert!(page.contains("<th>Model Exchange tolerance</th><td>any</td>"), "controller: any tolerance");
    let page = boomsim_tools::pack::documentation::<boomsim::models::HydraulicBoom>(Version::Fmi2, platforms);
    assert!(page.contains("<th>Model Exchange tolerance</th><td>1e-6 or tighter"), "HydraulicBoom: 1e-6");
    // FMI 3.0: the inputs a master ramps by intermediate update (the circuit's stroke follows the
    // integral of v: not one of them), and the early return at the event indicators.
    let page = boomsim_tools::pack::documentation::<boomsim::models::HydraulicCircuit>(Version::Fmi3, platforms);
    assert!(page.contains("intermediate update") && page.contains("<td>valve.u_ref, cylinder.v, port.c_m</td>"));
    assert!(page.contains("a step ends at an event indicator's root"), "early return");
}

/// The two halves of the cut carry the same coupling recipe (start.F, Z_c, step order, end stops).
#[test]
fn the_split_models_pages_carry_the_coupling_recipe() {
    use boomsim_tools::pack::documentation;
    use boomsim::models::{BoomMechanics, HydraulicCircuit};
    for page in
        [documentation::<HydraulicCircuit>(Version::Fmi2, &[]), documentation::<BoomMechanics>(Version::Fmi2, &[])]
    {
        assert!(page.contains("<h2>Coupling recipe</h2>") && page.contains("start.F") && page.contains("port.Z_c"));
    }
}

/// The pages' figures. The schematic of the two circuit FMUs names every line's pressure and
/// flow and every valve opening as the table does. The controller's plotted step response is
/// eq. 6.2's: for G_f(s) = K_f s / (s / omega_f + 1), a step of p by dp gives
/// u_comp(t) = K_f omega_f dp / Q_rated e^(-omega_f t), so the caption's numbers (sampled at
/// 1 ms after the step and at the first communication point 1/omega_f later, rounded to 0.01 %)
/// are the analytic ones to their rounding. HydraulicBoom's lowering run ends lower than it starts.
#[test]
fn the_pages_figures_follow_the_models() {
    use boomsim_tools::pack::documentation;
    use boomsim::fmu::Model;
    use boomsim::models::{HydraulicCircuit, PressureFeedbackController as Pfc};
    let names = [
        "p1",
        "p2",
        "p3",
        "p4",
        "Q1",
        "Q2",
        "Q3",
        "Q4",
        "valve.u",
        "valve.x_v",
        "cbv.u_cv",
        "cbv.u_cbv",
        "pcv.u",
        "valve.p_x",
        "cylinder.x",
        "cylinder.F",
    ];
    let page = documentation::<HydraulicCircuit>(Version::Fmi2, &[]);
    let svg = &page[page.find("<svg").unwrap()..page.find("</svg>").unwrap()];
    for n in names {
        assert!(HydraulicCircuit::VARIABLES.iter().any(|v| v.name == n), "{n} is a variable");
        assert!(
            svg.contains(&format!("{n},")) || svg.contains(&format!("{n}<")) || svg.contains(&format!("{n} ")),
            "{n} in the schematic"
        );
    }
    let number = |page: &str, after: &str| -> f64 {
        let rest = &page[page.find(after).unwrap_or_else(|| panic!("\"{after}\" in the caption")) + after.len()..];
        rest.split(' ').next().unwrap().parse().unwrap()
    };
    let param = |name: &str| match Pfc::VARIABLES.iter().find(|v| v.name == name).unwrap().kind {
        Kind::Real { start, .. } => start,
        _ => panic!("{name} is Real"),
    };
    let page = documentation::<Pfc>(Version::Fmi2, &[]);
    let (k_f, omega, q) = (param("K_f"), param("omega_f"), param("Q_rated"));
    let amplitude = 100.0 * k_f * omega * 1e5 / q;
    let h = Pfc::INFO.step_size;
    let later = ((1.0 / omega) / h).ceil() * h + h;
    assert!((number(&page, "u_comp jumps to ") - amplitude * (-omega * h).exp()).abs() <= 0.005 + 1e-9);
    assert!((number(&page, "later is ") - amplitude * (-omega * later).exp()).abs() <= 0.005 + 1e-9);
    let page = documentation::<boomsim::models::HydraulicBoom>(Version::Fmi2, &[]);
    let rest = &page[page.find("the stroke falls from ").expect("the lowering caption")..];
    let stroke: Vec<f64> = rest.split(' ').filter_map(|w| w.parse().ok()).take(2).collect();
    // It starts at start.x (480 mm, the experiments' start stroke, thesis chapter 7) and lowers.
    assert_eq!(stroke[0], 480.0);
    assert!(stroke[1] < stroke[0], "{stroke:?}");
}
