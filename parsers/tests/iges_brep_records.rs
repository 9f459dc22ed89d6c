//! The B-rep and structure records (IGES 5.3 types 141, 143, 186, 308, 402 groups, 408,
//! 502, 514):
//! hand-formatted fixtures decode field by field, and the topology records written by the
//! crate's writer parse back to the same records.
// Test helpers outside #[test] functions may unwrap and panic too.
#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic)]

mod iges_support;

use iges_support::{Builder, De};
use nurbsx_parsers::iges::{
    self, DirectoryEntry, ErrorKind, Global,
    records::{
        Boundary141, BoundaryCurve, BoundedSurface143, BrepSolid186, CompositeCurve102,
        CurveOnSurface142, Edge, EdgeList504, Face510, Group402, Loop508, LoopEdge, Shell514,
        SubfigureDefinition308, SubfigureInstance408, TrimmedSurface144, VertexList502,
    },
    writer::{WriteParams, write_with},
};

const GLOBAL: &str = ",,4Htest,8Hfile.igs,6Hnurbsx,3H0.1,32,38,6,308,15,,1.,2,2HMM,1,0.01,15H20260101.120000,1.E-7,100.,,,11,0,15H20260101.120000,;";

fn ty(ty: i64) -> De<'static> {
    De {
        ty,
        ..De::default()
    }
}

#[test]
fn brep_records_decode_by_their_declarations() {
    let mut b = Builder::new(GLOBAL);
    let vl = b.entity(ty(502), "502,2,1.,2.,3.,4.5,5.,6.;"); // D1
    let sh = b.entity(
        De {
            ty: 514,
            form: 1,
            ..De::default()
        },
        "514,2,9,1,11,0;",
    ); // D3
    let so = b.entity(ty(186), "186,3,1,1,3,0;"); // D5
    let bd = b.entity(ty(141), "141,1,2,31,2,21,1,1,23,25,2,0;"); // D7
    let bs = b.entity(ty(143), "143,1,31,1,7;"); // D9
    let sf = b.entity(ty(308), "308,0,4HPART,2,1,3;"); // D11
    let si = b.entity(ty(408), "408,11,1.,2.,3.,2.;"); // D13
    let si1 = b.entity(ty(408), "408,11,1.,2.,3.;"); // D15
    let short = b.entity(ty(514), "514,2,9,1;"); // D17
    let group = b.entity(
        De {
            ty: 402,
            form: 7,
            ..De::default()
        },
        "402,3,9,11,13;",
    ); // D19
    let text = b.build();
    let file = iges::parse(&text).unwrap();
    let entry = |de: usize| file.entry(i64::try_from(de).unwrap()).unwrap();
    assert_eq!(
        file.decode::<VertexList502>(entry(vl)).record.unwrap(),
        VertexList502 {
            points: vec![[1.0, 2.0, 3.0], [4.5, 5.0, 6.0]]
        }
    );
    assert_eq!(
        file.decode::<Shell514>(entry(sh)).record.unwrap(),
        Shell514 {
            faces: vec![(9, 1), (11, 0)],
            form: 1
        }
    );
    assert_eq!(
        file.decode::<Group402>(entry(group)).record.unwrap(),
        Group402 {
            members: vec![9, 11, 13],
            form: 7
        }
    );
    assert_eq!(
        file.decode::<BrepSolid186>(entry(so)).record.unwrap(),
        BrepSolid186 {
            shell: (3, 1),
            voids: vec![(3, 0)]
        }
    );
    assert_eq!(
        file.decode::<Boundary141>(entry(bd)).record.unwrap(),
        Boundary141 {
            kind: 1,
            preferred: 2,
            surface: 31,
            curves: vec![
                BoundaryCurve {
                    curve: 21,
                    sense: 1,
                    parameter_curves: vec![23]
                },
                BoundaryCurve {
                    curve: 25,
                    sense: 2,
                    parameter_curves: vec![]
                },
            ]
        }
    );
    assert_eq!(
        file.decode::<BoundedSurface143>(entry(bs)).record.unwrap(),
        BoundedSurface143 {
            kind: 1,
            surface: 31,
            boundaries: vec![7]
        }
    );
    assert_eq!(
        file.decode::<SubfigureDefinition308>(entry(sf))
            .record
            .unwrap(),
        SubfigureDefinition308 {
            depth: 0,
            name: Some("PART".into()),
            members: vec![1, 3]
        }
    );
    assert_eq!(
        file.decode::<SubfigureInstance408>(entry(si))
            .record
            .unwrap(),
        SubfigureInstance408 {
            definition: 11,
            translation: [1.0, 2.0, 3.0],
            scale: 2.0
        }
    );
    assert_eq!(
        file.decode::<SubfigureInstance408>(entry(si1))
            .record
            .unwrap()
            .scale,
        1.0
    );
    // The pointer walk of the solid: outer shell then the void, with their target types.
    let refs = file.references(entry(so)).unwrap().unwrap();
    assert_eq!(
        refs.iter().map(|&(n, p, t)| (n, p, t)).collect::<Vec<_>>(),
        vec![("SHELL", 3, &[514][..]), ("VOID", 3, &[514][..])]
    );
    // Arity: N = 2 faces need 5 parameters, the record holds 3.
    let e = file.decode::<Shell514>(entry(short)).record.unwrap_err();
    assert!(
        matches!(
            &e.kind,
            ErrorKind::Truncated {
                needed: 5,
                present: 3,
                ..
            }
        ),
        "{e}"
    );
}

/// The topology records the IGES writer emits, written by the crate's writer and parsed
/// back: every field survives.
#[test]
fn topology_records_write_and_read_back() {
    let records: Vec<(i64, i64, Box<dyn WriteParams>)> = vec![
        (
            102,
            0,
            Box::new(CompositeCurve102 {
                members: vec![17, 19],
            }),
        ),
        (
            142,
            0,
            Box::new(CurveOnSurface142 {
                creation: 0,
                surface: 15,
                parameter_curve: 1,
                model_curve: 1,
                preferred: 2,
            }),
        ),
        (
            144,
            0,
            Box::new(TrimmedSurface144 {
                surface: 15,
                outer_given: 1,
                outer: 3,
                inner: vec![3, 3],
            }),
        ),
        (
            502,
            1,
            Box::new(VertexList502 {
                points: vec![[0.1, 0.2, 0.3], [1e-300, -4.0, 5.5]],
            }),
        ),
        (
            504,
            1,
            Box::new(EdgeList504 {
                edges: vec![Edge {
                    curve: 17,
                    start: (7, 1),
                    end: (7, 2),
                }],
            }),
        ),
        (
            508,
            1,
            Box::new(Loop508 {
                edges: vec![LoopEdge {
                    kind: 0,
                    edge: 9,
                    index: 1,
                    orientation: 0,
                    parameter_curves: vec![(0, 19)],
                }],
            }),
        ),
        (
            510,
            1,
            Box::new(Face510 {
                surface: 15,
                outer_first: 1,
                loops: vec![11],
            }),
        ),
        (
            514,
            1,
            Box::new(Shell514 {
                faces: vec![(13, 1)],
                form: 1,
            }),
        ),
        (
            186,
            0,
            Box::new(BrepSolid186 {
                shell: (15, 1),
                voids: vec![],
            }),
        ),
        (
            402,
            7,
            Box::new(Group402 {
                members: vec![5, 13],
                form: 7,
            }),
        ),
    ];
    let des: Vec<DirectoryEntry> = records
        .iter()
        .map(|&(t, form, _)| DirectoryEntry {
            entity_type: t,
            form,
            ..DirectoryEntry::default()
        })
        .collect();
    let global = Global {
        param_delimiter: ',',
        record_delimiter: ';',
        ..Global::default()
    };
    let text = write_with("test", &global, &des, 0, |i, w| {
        records[i].2.write_params(w)
    })
    .unwrap();
    let file = iges::parse(&text).unwrap();
    let e = |i: usize| file.entries[i].as_ref().unwrap();
    assert_eq!(
        file.decode::<CompositeCurve102>(e(0))
            .record
            .unwrap()
            .members,
        vec![17, 19]
    );
    assert_eq!(
        file.decode::<CurveOnSurface142>(e(1)).record.unwrap(),
        CurveOnSurface142 {
            creation: 0,
            surface: 15,
            parameter_curve: 1,
            model_curve: 1,
            preferred: 2,
        }
    );
    assert_eq!(
        file.decode::<TrimmedSurface144>(e(2)).record.unwrap().inner,
        vec![3, 3]
    );
    assert_eq!(
        file.decode::<VertexList502>(e(3)).record.unwrap().points,
        vec![[0.1, 0.2, 0.3], [1e-300, -4.0, 5.5]]
    );
    assert_eq!(
        file.decode::<EdgeList504>(e(4)).record.unwrap().edges[0].end,
        (7, 2)
    );
    assert_eq!(
        file.decode::<Loop508>(e(5)).record.unwrap().edges[0].parameter_curves,
        vec![(0, 19)]
    );
    assert_eq!(file.decode::<Face510>(e(6)).record.unwrap().loops, vec![11]);
    assert_eq!(
        file.decode::<Shell514>(e(7)).record.unwrap(),
        Shell514 {
            faces: vec![(13, 1)],
            form: 1
        }
    );
    assert_eq!(
        file.decode::<BrepSolid186>(e(8)).record.unwrap().shell,
        (15, 1)
    );
    assert_eq!(
        file.decode::<Group402>(e(9)).record.unwrap(),
        Group402 {
            members: vec![5, 13],
            form: 7
        }
    );
}
