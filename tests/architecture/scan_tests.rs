//! The scanner on small snippets: what it must not be fooled by.

use crate::scan::{FnSpan, scan};

/// `(name, first line, lines, test)` of every fn found.
fn fns(src: &str) -> Vec<(String, usize, usize, bool)> {
    scan(src)
        .fns
        .into_iter()
        .map(
            |FnSpan {
                 name,
                 line,
                 lines,
                 test,
             }| (name, line, lines, test),
        )
        .collect()
}

fn f(name: &str, line: usize, lines: usize, test: bool) -> (String, usize, usize, bool) {
    (name.to_string(), line, lines, test)
}

#[test]
fn a_fn_spans_from_its_keyword_to_its_closing_brace() {
    let src = "/// doc\n#[inline]\npub fn a(x: u32) -> u32 {\n    x + 1\n}\n\nfn b() {}\n";
    assert_eq!(fns(src), [f("a", 3, 3, false), f("b", 7, 1, false)]);
}

#[test]
fn braces_in_strings_chars_and_comments_are_not_counted() {
    let src = r####"fn a() {
    let s = "}{ \" }";
    let r = r#"}"# ;
    let rr = r##"a "# }"##;
    let b = b"}";
    let c = '}';
    let e = '\'';
    let u = '\u{7d}';
    // }
    /* } /* nested } */ } */
    let q = br"}";
}
fn b() {}
"####;
    assert_eq!(fns(src), [f("a", 1, 12, false), f("b", 13, 1, false)]);
}

#[test]
fn lifetimes_and_labels_are_not_chars() {
    let src = "fn a<'a>(x: &'a str) -> &'a str {\n    'outer: loop { break 'outer; }\n    x\n}\n";
    assert_eq!(fns(src), [f("a", 1, 4, false)]);
}

#[test]
fn nested_fns_and_closures() {
    let src =
        "fn outer() {\n    let c = |x: u32| { x };\n    fn inner() {\n        c(1);\n    }\n}\n";
    assert_eq!(fns(src), [f("outer", 1, 6, false), f("inner", 3, 3, false)]);
}

#[test]
fn methods_are_named_with_their_type_and_declarations_are_skipped() {
    let src = "impl<T: Fn() -> u8> a::Wrap<T> {\n    fn new() -> Self { todo!() }\n}\n\
               impl std::fmt::Display for Thing<'_> {\n    fn fmt(&self) {}\n}\n\
               trait Shape: Sized {\n    fn area(&self) -> f64;\n    fn twice(&self) -> f64 {\n        2.0\n    }\n}\n\
               fn free() -> impl Iterator<Item = u8> { std::iter::empty() }\n";
    assert_eq!(
        fns(src),
        [
            f("Wrap::new", 2, 1, false),
            f("Thing::fmt", 5, 1, false),
            f("Shape::twice", 9, 3, false),
            f("free", 13, 1, false),
        ]
    );
}

#[test]
fn fn_pointer_types_and_array_types_are_no_items() {
    let src = "fn a(f: fn(u32) -> u32, x: [u8; 3]) -> u32 {\n    let g: fn() = b;\n    0\n}\n";
    assert_eq!(fns(src), [f("a", 1, 4, false)]);
}

#[test]
fn cfg_test_items_are_test_code() {
    let src = "fn prod() {}\n#[cfg(test)]\nmod tests {\n    use super::*;\n    #[test]\n    fn t() {\n        prod();\n    }\n}\n\
               #[cfg(test)]\nfn helper() {}\n#[cfg(test)]\nimpl Thing {\n    fn made() {}\n}\n\
               #[cfg(test)]\nuse std::fmt;\nfn after() {}\n";
    assert_eq!(
        fns(src),
        [
            f("prod", 1, 1, false),
            f("t", 6, 3, true),
            f("helper", 11, 1, true),
            f("Thing::made", 14, 1, true),
            f("after", 18, 1, false),
        ]
    );
}

#[test]
fn cfg_test_module_files_are_named() {
    let src =
        "mod a;\n#[cfg(test)]\nmod tests;\n#[cfg(test)]\npub(crate) mod fixtures;\nfn b() {}\n";
    let s = scan(src);
    assert_eq!(s.test_mods, ["tests", "fixtures"]);
    assert_eq!(s.fns.len(), 1);
    assert!(!s.fns[0].test);
}

#[test]
fn other_attributes_leave_code_production() {
    let src = "#[cfg_attr(not(test), allow(dead_code))]\nfn a() {}\n#[cfg(not(test))]\nfn b() {}\n";
    assert_eq!(fns(src), [f("a", 2, 1, false), f("b", 4, 1, false)]);
}
