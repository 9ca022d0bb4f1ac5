//! Keys that moved to their stage's table or went: an old case file (or `--set`) gets one
//! line naming the key's new place, or why it went.

use crate::setup::error::{field_err, FieldError};

/// An old dotted key and what became of it.
#[derive(Clone, Copy, Debug)]
pub struct Renamed {
    pub old: &'static str,
    pub fate: Fate,
}

const fn moved(old: &'static str, new: &'static str) -> Renamed {
    Renamed {
        old,
        fate: Fate::MovedTo(new),
    }
}

const fn removed(old: &'static str, why: &'static str) -> Renamed {
    Renamed {
        old,
        fate: Fate::Removed(why),
    }
}

/// Why the wall pressure's momentum balance went.
const WALL_PRESSURE_GONE: &str = "the wall pressure's momentum balance (`momentum`) lost on \
    the confined cylinder (breakdown at t = 0.44) and no case used it; walls carry the \
    Neumann pressure; see the decision log";

/// What became of an old key.
#[derive(Clone, Copy, Debug)]
pub enum Fate {
    /// Now at this dotted key, with the same values.
    MovedTo(&'static str),
    /// Removed; why, and what to use instead.
    Removed(&'static str),
}

/// Old dotted keys and their fates.
#[rustfmt::skip]
pub const RENAMED: &[Renamed] = &[
    moved("scheme.ppe_solver",                    "scheme.ppe.solver"),
    moved("scheme.preconditioner",                "scheme.ppe.preconditioner"),
    moved("scheme.ppe_tolerance",                 "scheme.ppe.tolerance"),
    moved("scheme.ppe_divergence_tolerance",      "scheme.ppe.divergence_tolerance"),
    moved("scheme.ppe_max_iterations",            "scheme.ppe.max_iterations"),
    moved("scheme.ppe_warm_start",                "scheme.ppe.warm_start"),
    moved("scheme.volume_relaxation",             "experimental.volume_relaxation"),
    moved("scheme.ppe_laplacian",                 "experimental.ppe_laplacian"),
    moved("scheme.sound_speed",                   "scheme.wcsph.sound_speed"),
    moved("scheme.mach",                          "scheme.wcsph.mach"),
    moved("scheme.artificial_viscosity",          "scheme.wcsph.artificial_viscosity"),
    moved("scheme.artificial_viscosity_beta",     "scheme.wcsph.artificial_viscosity_beta"),
    moved("scheme.artificial_viscosity_velocity", "scheme.wcsph.artificial_viscosity_velocity"),
    moved("scheme.artificial_stress",             "scheme.wcsph.artificial_stress"),
    moved("scheme.artificial_stress_exponent",    "scheme.wcsph.artificial_stress_exponent"),
    moved("scheme.density_diffusion",             "scheme.wcsph.density_diffusion"),
    moved("scheme.sound_speed_stress_factor",     "scheme.wcsph.sound_speed_stress_factor"),
    moved("scheme.free_surface_pressure",         "scheme.free_surface.pressure"),
    moved("scheme.surface_gradient",              "experimental.surface_gradient"),
    moved("scheme.contact_line_rows",             "experimental.contact_rows"),
    moved("scheme.surface_indicator",             "experimental.surface_indicator"),
    moved("scheme.surface_shear",                 "experimental.surface_shear"),
    moved("scheme.detached_momentum",             "scheme.free_surface.detached_momentum"),
    moved("scheme.surface_repulsion",             "scheme.free_surface.repulsion"),
    moved("scheme.surface_tension",               "scheme.surface_tension.form"),
    moved("scheme.capillary_time_level",          "scheme.surface_tension.time_level"),
    moved("scheme.contact_curvature",             "experimental.contact_curvature"),
    moved("scheme.contact_angle_at",              "experimental.contact_angle_at"),
    moved("scheme.wall_model",                    "scheme.walls.model"),
    moved("scheme.wall_velocity",                 "scheme.walls.velocity"),
    removed("scheme.wall_pressure",               WALL_PRESSURE_GONE),
    moved("scheme.wall_conformation",             "scheme.walls.conformation"),
    moved("scheme.conformation",                  "scheme.conformation.form"),
    moved("scheme.conformation_integrator",       "scheme.conformation.integrator"),
    moved("scheme.conformation_remap",            "scheme.conformation.remap"),
    moved("scheme.constitutive_gradient",         "experimental.velocity_gradient"),
    moved("scheme.evss_alpha",                    "scheme.conformation.evss_alpha"),
    moved("scheme.hourglass_control",             "scheme.conformation.hourglass_control"),
    moved("scheme.time_step",                     "scheme.time_step.fixed"),
    moved("scheme.dt_factor",                     "scheme.time_step.factor"),
    moved("scheme.gradient_order",                "scheme.operators.gradient"),
    moved("scheme.laplacian_order",               "scheme.operators.laplacian"),
    moved("scheme.neighbour_skin",                "scheme.neighbours.skin"),
    moved("scheme.reorder",                       "scheme.neighbours.reorder"),
    moved("scheme.ppe.volume_relaxation",         "experimental.volume_relaxation"),
    moved("scheme.ppe.laplacian",                 "experimental.ppe_laplacian"),
    moved("scheme.free_surface.gradient",         "experimental.surface_gradient"),
    moved("scheme.free_surface.contact_rows",     "experimental.contact_rows"),
    moved("scheme.free_surface.indicator",        "experimental.surface_indicator"),
    moved("scheme.free_surface.shear",            "experimental.surface_shear"),
    moved("scheme.wetting.curvature",             "experimental.contact_curvature"),
    moved("scheme.wetting.angle_at",              "experimental.contact_angle_at"),
    removed("scheme.walls.pressure",              WALL_PRESSURE_GONE),
    removed("experimental.wall_pressure",         WALL_PRESSURE_GONE),
    moved("scheme.conformation.velocity_gradient","experimental.velocity_gradient"),
];

/// The first old key present in a parsed case table, as the error a user sees.
pub fn refuse_old_keys(table: &toml::Table) -> Result<(), FieldError> {
    for &Renamed { old, fate } in RENAMED {
        if !present(table, old) {
            continue;
        }
        return Err(field_err(
            old,
            match fate {
                Fate::MovedTo(new) => format!("this key is now `{new}`"),
                Fate::Removed(why) => format!("this key was removed: {why}"),
            },
        ));
    }
    Ok(())
}

fn present(table: &toml::Table, dotted: &str) -> bool {
    let mut parts = dotted.split('.').peekable();
    let mut current = table;
    while let Some(part) = parts.next() {
        match (current.get(part), parts.peek()) {
            // A key that became a table of the same name is the new layout.
            (Some(v), None) => return !v.is_table(),
            (Some(toml::Value::Table(t)), Some(_)) => current = t,
            _ => return false,
        }
    }
    false
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::setup::error::read_table;

    #[test]
    fn an_old_key_names_its_new_place() {
        let table: toml::Table = toml::from_str("[scheme]\nppe_solver = \"lu\"").unwrap();
        let (field, message) = refuse_old_keys(&table).unwrap_err();
        assert_eq!(field, "scheme.ppe_solver");
        assert!(message.contains("`scheme.ppe.solver`"), "{message}");
        let table: toml::Table = toml::from_str("[scheme.ppe]\nsolver = \"lu\"").unwrap();
        assert!(refuse_old_keys(&table).is_ok());
    }

    #[test]
    fn a_removed_key_says_why() {
        for case in [
            "[experimental]\nwall_pressure = \"momentum\"",
            "[scheme.walls]\npressure = \"neumann\"",
            "[scheme]\nwall_pressure = \"momentum\"",
        ] {
            let table: toml::Table = toml::from_str(case).unwrap();
            let (field, message) = refuse_old_keys(&table).unwrap_err();
            assert!(field.ends_with("pressure"), "{field}");
            assert!(message.starts_with("this key was removed: "), "{message}");
            assert!(message.contains("decision log"), "{message}");
        }
    }

    /// Whether `[scheme]` or `[experimental]` reads `dotted` (a key it does not know is refused
    /// as unknown; one it knows refuses the value `[]`, which none takes, by its type).
    fn scheme_reads(dotted: &str) -> bool {
        let mut table = toml::Table::new();
        crate::setup::overrides::apply_override(&mut table, &format!("{dotted}=[]")).unwrap();
        let read = match dotted.split('.').next() {
            Some("experimental") => {
                let value = table.remove("experimental").expect("an experimental key");
                read_table::<crate::setup::experimental::ExperimentalSpec>(value, "").map(drop)
            }
            _ => {
                let value = table.remove("scheme").expect("a scheme key");
                read_table::<crate::setup::schema::SchemeSpec>(value, "").map(drop)
            }
        };
        match read {
            Ok(()) => true,
            Err((_, message)) => !message.starts_with("unknown field"),
        }
    }

    #[test]
    fn every_new_place_is_a_key_the_case_file_reads() {
        for &Renamed { old, fate } in RENAMED {
            match fate {
                Fate::MovedTo(new) => {
                    assert!(scheme_reads(new), "{old} -> {new}: not a key");
                    // A key that became a table of its own name is still read, as that table.
                    if !new.starts_with(&format!("{old}.")) {
                        assert!(!scheme_reads(old), "{old} is still read");
                    }
                }
                Fate::Removed(_) => assert!(!scheme_reads(old), "{old} is still read"),
            }
        }
    }
}
