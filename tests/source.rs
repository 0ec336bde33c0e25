//! The realization source of the library (src/source.rs): what the
//! command line's point-source options resolve into.

use varspec::registry;
use varspec::rng::set_rng;
use varspec::source::{Source, SourceError};

#[test]
fn a_sampler_source_draws_realization_r_from_stream_seed_r() {
    let sampler = registry::build("umj", 64, None, &[]).unwrap();
    let expected = sampler.sample(&mut set_rng(5, 3)).unwrap();
    let source = Source::Sampler {
        sampler,
        seed: 5,
        sets: 4,
        dims: Some(vec![0, 2]),
        name: "umj N=64".into(),
    };
    assert_eq!(source.count(), 4);
    assert_eq!(source.get(3).unwrap(), expected.projected(&[0, 2]).unwrap());
    // Beyond its sets a sampler draws fresh realizations.
    assert_eq!(
        source.get_cyclic(7).unwrap(),
        source.get(7).unwrap(),
        "cyclic reuse is for files only"
    );
}

#[test]
fn a_file_source_reuses_its_sets_cyclically_and_names_itself_in_errors() {
    let sampler = registry::build("jitter", 27, Some(3), &[]).unwrap();
    let sets: Vec<_> = (0..3)
        .map(|r| sampler.sample(&mut set_rng(1, r)).unwrap())
        .collect();
    let source = Source::File {
        sets: sets.clone(),
        dims: None,
        name: "sets.csv".into(),
    };
    assert_eq!(source.get_cyclic(4).unwrap(), sets[1]);
    assert_eq!(source.points_per_set(), 27);
    let bad = Source::File {
        sets,
        dims: Some(vec![0, 5]),
        name: "sets.csv".into(),
    };
    match bad.get(0) {
        Err(e @ SourceError::Projection { .. }) => {
            assert!(e.to_string().starts_with("sets.csv: "), "{e}")
        }
        other => panic!("expected a projection error, got {other:?}"),
    }
}
