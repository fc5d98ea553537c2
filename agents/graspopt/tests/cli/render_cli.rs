//! `graspopt trial --preview FILE.png`: a two-view picture of the grasp.

use crate::support::{decode_png as decode, graspopt, graspopt_ok, tempdir};

/// The contact dots' colour (`render::CONTACT_COLOUR`).
const DOT: [u8; 3] = [230, 20, 20];

#[test]
fn preview_shows_the_grasp_from_two_sides() {
    let dir = tempdir("mug");
    let path = dir.join("mug.png");
    let p = path.to_str().unwrap();
    let out = graspopt_ok(&[
        "trial",
        "--object",
        "mug",
        "--at",
        "x=-0.09",
        "--preview",
        p,
    ]);
    let stdout = String::from_utf8(out.stdout).unwrap();
    assert!(stdout.contains(&format!("wrote {p}")), "{stdout}");
    assert!(stdout.contains("force closure"), "{stdout}");
    let (w, h, px) = decode(&path);
    assert_eq!((w, h), (1200, 560));
    assert!(px.iter().any(|c| *c != px[0]), "uniform picture");
    for half in [0..w / 2, w / 2..w] {
        let pixels: Vec<[u8; 3]> = (0..h)
            .flat_map(|y| half.clone().map(move |x| (x, y)))
            .map(|(x, y)| px[(y * w + x) as usize])
            .collect();
        // The contact dots, the (blue, shaded) object and the (orange, shaded) hand show.
        assert!(pixels.contains(&DOT), "no contact dot in {half:?}");
        let blue = pixels
            .iter()
            .filter(|[r, g, b]| b > g && g > r && *b > 80)
            .count();
        let orange = pixels
            .iter()
            .filter(|[r, g, b]| r > g && g > b && *r > 80 && *g > 40)
            .count();
        assert!(blue > 1000 && orange > 1000, "{half:?}: {blue} {orange}");
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn preview_of_a_missed_grasp_still_draws_the_scene() {
    let dir = tempdir("miss");
    let path = dir.join("miss.png");
    graspopt_ok(&[
        "trial",
        "--object",
        "sphere",
        "--at",
        "x=-0.16",
        "--preview",
        path.to_str().unwrap(),
    ]);
    let (w, h, px) = decode(&path);
    assert_eq!((w, h), (1200, 560));
    assert!(!px.contains(&DOT));
    assert!(px.iter().any(|c| *c != px[0]));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_preview_path_is_named() {
    let path = "/nonexistent-graspopt-dir/preview.png";
    let out = graspopt(&[
        "trial",
        "--object",
        "sphere",
        "--at",
        "x=-0.1",
        "--preview",
        path,
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains(path) && stderr.contains("PNG"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
