//! The back ends' declared parameters against the parser and their word enums (the passes'
//! are checked in `robovec-passes`' `params::tests`).

use robovec_passes::params::Word;
use robovec_passes::{Params, PassError, PassInfo};

fn build(info: &'static PassInfo, raw: &[(&str, String)]) -> Result<String, PassError> {
    let raw: Vec<(String, Option<String>)> = raw.iter().map(|(k, v)| (k.to_string(), Some(v.clone()))).collect();
    let p = Params::check(info, &raw)?;
    Ok(format!("{:?}", (info.build)(&p)?))
}

#[test]
fn a_set_parameter_takes_only_its_values() {
    let info = crate::REGISTRY.get("codegen").unwrap();
    let batch = info.param("batch").unwrap();
    assert_eq!((batch.default_text(), batch.range_text()), ("1".to_string(), "1|2|4|8|16".to_string()));
    for bad in ["0", "3", "32", "-1", "x"] {
        let e = build(info, &[("batch", bad.into())]).unwrap_err().to_string();
        assert_eq!(
            e,
            format!("pass `codegen`: parameter `batch` must be one of `1`, `2`, `4`, `8`, `16`, found `{bad}`")
        );
    }
}

#[test]
fn word_parameters_are_read_as_their_enums() {
    use crate::c::{Abi, Precision, Trig};
    use crate::fpga::Format;
    use robovec_machine::resources::Logic;
    fn round_trip<T: Word + PartialEq + std::fmt::Debug>(all: &[T]) {
        assert_eq!(all.len(), T::WORDS.len());
        for (x, w) in all.iter().zip(T::WORDS) {
            assert_eq!((x.as_str(), T::from_word(w)), (*w, Some(*x)));
        }
        assert_eq!(T::from_word("x"), None);
    }
    round_trip(&[Abi::Plain, Abi::Robotran, Abi::Pinocchio]);
    round_trip(&[Precision::F64, Precision::F32]);
    round_trip(&[Trig::Libm, Trig::Input, Trig::Inline]);
    round_trip(&[Format::Both, Format::Mif, Format::Hex]);
    round_trip(&[Logic::Auto, Logic::Yosys, Logic::Estimate, Logic::Pnr]);
    assert_eq!(serde_json::to_string(&Abi::Robotran).unwrap(), "\"robotran\"");
}
