use super::*;
use proptest::prelude::*;

/// A remote address gets at most its share of places; loopback, which every local program
/// shares, only the total.
#[test]
fn the_per_address_limit_spares_loopback() {
    let cfg = RelayConfig { max_clients: 5, max_clients_per_address: 2, ..Default::default() };
    let shared = Shared::new(Blackboard::new(1, Arc::new(mrt_core::WallClock::new())), cfg);
    let remote: IpAddr = "192.0.2.7".parse().unwrap();
    assert!(shared.admit(remote).is_ok() && shared.admit(remote).is_ok());
    let refused = shared.admit(remote).unwrap_err();
    assert_eq!(refused.line(), "ERR 503 too many clients from 192.0.2.7");
    let local: IpAddr = "127.0.0.1".parse().unwrap();
    for _ in 0..3 {
        shared.admit(local).unwrap();
    }
    assert_eq!(shared.admit(local).unwrap_err().line(), "ERR 503 too many clients");
    shared.leave(remote);
    assert!(shared.admit(remote).is_ok(), "a place given back is taken again");
}

#[test]
fn every_command_parses() {
    let p = |l: &str| parse_request(l).unwrap().unwrap();
    assert_eq!(p("REFR 250"), Request::Refr(250));
    assert_eq!(
        p("ADDW local.var.machine.*"),
        Request::Addw(Pattern::parse("local.var.machine.*").unwrap())
    );
    assert_eq!(p("DELW *.var.x"), Request::Delw(Pattern::parse("*.var.x").unwrap()));
    assert_eq!(p("clrw\r"), Request::Clrw);
    assert_eq!(p("LSTW"), Request::Lstw);
    assert_eq!(
        p("SETV local.var.a String \"two words\""),
        Request::Setv("local.var.a".into(), Value::String("two words".into()))
    );
    assert_eq!(p("GETV 2.var.machine.role"), Request::Getv("2.var.machine.role".into()));
    assert_eq!(p("LSTV"), Request::Lstv(None));
    assert_eq!(p("QUIT"), Request::Quit);
    assert_eq!(p("AUTH s3cret"), Request::Auth("s3cret".into()));
    assert_eq!(parse_request("   ").unwrap(), None);
    assert_eq!(p("LSTV *"), Request::Lstv(None));
    assert_eq!(p("LSTV * -"), Request::LstvPage(None, None));
    assert_eq!(
        p("LSTV local.* local.var.a"),
        Request::LstvPage(Some(Pattern::parse("local.*").unwrap()), Some("local.var.a".into()))
    );
}

#[test]
fn tokens_are_one_word_and_compared_whole() {
    assert!(check_token("s3cret-ä").is_ok());
    assert_eq!(check_token(""), Err("it is empty"));
    assert!(check_token("a b").is_err() && check_token("a\u{1b}").is_err());
    assert!(check_token(&"x".repeat(MAX_TOKEN_LEN + 1)).is_err());
    assert!(same_token("s3cret", "s3cret"));
    for wrong in ["", "s3cre", "s3cret2", "S3cret"] {
        assert!(!same_token(wrong, "s3cret"), "{wrong}");
    }
    assert!(parse_request("LSTV a b c").is_err());
}

#[test]
fn bad_requests_are_refused_with_a_reason() {
    let e = |l: &str| parse_request(l).unwrap_err().line();
    assert_eq!(e("HELO"), "ERR 400 unknown command `HELO`");
    assert_eq!(e("REFR 5"), "ERR 400 the refresh period is 10 to 60000 ms");
    assert_eq!(e("REFR fast"), "ERR 400 REFR takes a period in milliseconds");
    assert_eq!(e("ADDW"), "ERR 400 ADDW takes one argument");
    assert_eq!(e("CLRW now"), "ERR 400 CLRW takes no argument");
    assert_eq!(e("SETV local.var.a"), "ERR 400 SETV takes a symbol, a type and a value");
    assert_eq!(e("SETV local.var.a Int x"), "ERR 400 `x` is not a Int");
    assert!(e("GETV local.vr.a").starts_with("ERR 400 `local.vr.a`"));
}

proptest! {
    #[test]
    fn random_lines_never_panic(line in "\\PC{0,80}") {
        let _ = parse_request(&line);
    }

    #[test]
    fn random_commands_never_panic(cmd in "(REFR|ADDW|DELW|CLRW|LSTW|SETV|GETV|LSTV|QUIT|AUTH)", rest in "[ -~]{0,60}") {
        let _ = parse_request(&format!("{cmd} {rest}"));
    }
}
