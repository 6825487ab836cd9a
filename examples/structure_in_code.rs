//! Build a spacecraft in code, without a scenario file, and compute its modes: a free hub
//! with a tube mast and a plate wing at its tip, a lumped mass on the mast. SI units.
//!
//! Run: `cargo run --release --example structure_in_code`

use flexcraft::basis::BasisKind;
use flexcraft::math::Vec3;
use flexcraft::structure::{
    inertia_tensor, Attachment, Beam, BeamSection, BeamSpec, BeamTerms, Frame, Hub, HubMotion,
    LumpedMass, Material, Parts, Plate, PlateSpec, PlateStiffness, PlateTerms, Structure,
};
use flexcraft::{ModalAnalysis, RitzModel};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    // Every constructor validates its values (ranges, names, geometry) and says which field
    // it refused: e.g. a Poisson's ratio of 0.5 gives an error whose field() is PoissonRatio.
    let aluminium = Material::new(70e9, 0.3, 2700.0, None)?;
    let hub = Hub::new(
        HubMotion::Free,
        800.0,
        Vec3([-1.5, 0.0, 0.0]),
        inertia_tensor(&[900.0, 1200.0, 1200.0])?,
    )?;
    let mast = Beam::new(BeamSpec {
        name: "mast".into(),
        attachment: Attachment::Hub { point: Vec3::ZERO },
        frame: Frame::new(Vec3([1.0, 0.0, 0.0]), None)?,
        length: 13.0,
        material: aluminium,
        section: BeamSection::tube(0.30, 0.005)?,
        terms: BeamTerms::new(10, 6, 4)?,
    })?;
    // Parents are beam indices: the wing and the antenna sit on beam 0 (the mast).
    let wing = Plate::new(PlateSpec {
        name: "wing".into(),
        attachment: Attachment::Beam {
            beam: 0,
            station: 13.0,
        },
        length_axis: Vec3([1.0, 0.0, 0.0]),
        normal: Vec3([0.0, 0.0, 1.0]),
        length: 15.0,
        width: 3.75,
        stiffness: PlateStiffness::Homogeneous {
            thickness: 0.03,
            material: aluminium,
        },
        terms: PlateTerms::new(10, 6)?,
    })?;
    let antenna = LumpedMass::new(
        "antenna",
        Attachment::Beam {
            beam: 0,
            station: 6.5,
        },
        Vec3([0.0, 0.0, 0.5]),
        15.0,
        inertia_tensor(&[1.0, 8.0, 8.0])?,
    )?;
    let structure = Structure::new(Parts {
        name: "built in code".into(),
        hub,
        beams: vec![mast],
        plates: vec![wing],
        masses: vec![antenna],
        basis: BasisKind::Legendre,
    })?;
    println!(
        "{}: total mass {:.3} kg, {} beam(s), {} plate(s)",
        structure.name(),
        structure.total_mass(),
        structure.beams().len(),
        structure.plates().len()
    );

    let model = RitzModel::assemble(&structure);
    let modes = ModalAnalysis::compute(&model)?;
    println!("{} generalized coordinates", model.dof());
    println!("mode  kind        f [Hz]");
    for m in modes.modes.iter().take(12) {
        let kind = if m.rigid { "rigid" } else { "elastic" };
        println!("{:4}  {kind:8} {:10.6}", m.number, m.frequency_hz());
    }
    Ok(())
}
