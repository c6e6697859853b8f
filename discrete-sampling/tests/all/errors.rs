//! Bad weights are errors that name the first offending index, for every
//! constructor.

use discrete_sampling::{
    AliasTable, CdfBisection, DiscreteSampler, Distribution2D, Error, GuideTable,
};

fn all_constructors(weights: &[f64]) -> Vec<Result<(), Error>> {
    vec![
        CdfBisection::from_weights(weights).map(drop),
        GuideTable::from_weights(weights).map(drop),
        AliasTable::from_weights(weights).map(drop),
        Distribution2D::new(weights, weights.len(), 1).map(drop),
    ]
}

#[test]
fn each_kind_of_bad_weight_is_named() {
    let cases: Vec<(Vec<f64>, Error)> = vec![
        (vec![1.0, 2.0, f64::NAN, -1.0], Error::NaN { index: 2 }),
        (
            vec![1.0, -0.25, f64::NAN],
            Error::Negative {
                index: 1,
                value: -0.25,
            },
        ),
        (
            vec![0.0, f64::INFINITY],
            Error::Infinite {
                index: 1,
                value: f64::INFINITY,
            },
        ),
        (vec![0.0; 5], Error::AllZero { len: 5 }),
        (vec![f64::MAX; 3], Error::TotalOverflow),
    ];
    for (weights, expected) in cases {
        for result in all_constructors(&weights) {
            assert_eq!(result, Err(expected.clone()), "weights {weights:?}");
        }
    }
    for result in [
        CdfBisection::new::<f64>(&[]).map(drop),
        GuideTable::new::<f64>(&[]).map(drop),
        AliasTable::new::<f64>(&[]).map(drop),
    ] {
        assert_eq!(result, Err(Error::Empty));
    }
}

#[test]
fn two_d_errors_name_the_flat_index_and_the_shape() {
    let mut image = vec![1.0f32; 12];
    image[7] = -2.0;
    assert_eq!(
        Distribution2D::new(&image, 4, 3),
        Err(Error::Negative {
            index: 7,
            value: -2.0
        })
    );
    let err = Distribution2D::new(&[1.0; 12], 5, 3).unwrap_err();
    assert_eq!(
        err,
        Error::DimensionMismatch {
            width: 5,
            height: 3,
            expected: 15,
            len: 12
        }
    );
    assert!(err.to_string().contains("5×3"));
    assert!(matches!(
        Distribution2D::new::<f64>(&[], 0, 0),
        Err(Error::DimensionMismatch { .. })
    ));
    assert!(matches!(
        Distribution2D::new(&[1.0; 4], usize::MAX, 2),
        Err(Error::DimensionMismatch {
            expected: usize::MAX,
            ..
        })
    ));
}

#[test]
fn messages_say_what_and_where() {
    let msg = GuideTable::new(&[1.0, f64::NAN]).unwrap_err().to_string();
    assert_eq!(msg, "weight 1 is NaN");
    let msg = AliasTable::new(&[1.0, -3.0]).unwrap_err().to_string();
    assert!(msg.contains("weight 1") && msg.contains("-3"), "{msg}");
}
