fn main() {
    let path = std::env::args().nth(1).unwrap();
    let s = flexcraft::Scenario::from_file(std::path::Path::new(&path)).unwrap_or_else(|e| panic!("{e}"));
    let d = s.deployment.unwrap();
    let r = flexcraft::deploy::simulate(&d);
    for e in &r.latches {
        println!("t={:.6} hinge {} angles {:?} before {:?} after {:?} E {:.4}->{:.4}", e.time, e.hinge, e.angles, e.rates_before, e.rates_after, e.energy_before, e.energy_after);
        for (i, (f, m)) in e.impulses.iter().enumerate() { println!("   hinge {} S {:?} M {}", i+1, f, m); }
    }
    println!("all {} final {} evals {} swing {:?}", r.all_latched, r.final_time, r.evaluations, r.swing_back);
}
