//! Errors for common mistakes carry a hint: a path with a typo names the nearest file of its
//! folder, a cloud with too few points says what a scan looks like; both exit 2 and write
//! nothing.

mod common;

use common::subfit;

#[test]
fn a_path_typo_suggests_the_file_and_too_few_points_say_why() {
    let d = tempfile::tempdir().unwrap();
    let five = d.path().join("five.ply");
    std::fs::write(
        &five,
        "ply\nformat ascii 1.0\nelement vertex 5\nproperty float x\nproperty float y\nproperty float z\nend_header\n0 0 0\n1 0 0\n0 1 0\n0 0 1\n1 1 1\n",
    )
    .unwrap();
    let out = d.path().join("out");
    let typo = d.path().join("fiv.ply");
    let r = subfit(&["fit", typo.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains(&format!("did you mean {}?", five.display())),
        "{err}"
    );
    let far = d.path().join("unrelated-name.obj");
    let r = subfit(&["info", far.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert!(!err.contains("did you mean"), "{err}");

    let r = subfit(&["fit", five.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    let err = String::from_utf8_lossy(&r.stderr);
    assert_eq!(r.status.code(), Some(2), "{err}");
    assert!(
        err.contains("5 points given") && err.contains("hint:"),
        "{err}"
    );
    assert!(!out.exists(), "no partial output");
}
