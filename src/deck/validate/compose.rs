//! `topology FILE [offset auto|N]`, repeatable: the deck's system is the
//! topologies in order, composed by [`Topology::append`]'s rule.

use std::sync::Arc;

use super::{expect_len, options, Validator};
use crate::input::{parse_u64, InputError, SourceFile, Token};
use crate::topology::parse_topology;

impl Validator {
    pub(super) fn topology_command(&mut self, s: &[Token], usage: &str) -> Result<(), InputError> {
        expect_len(s, 1..=3, usage)?;
        let opts = options(&s[2..], &["offset"], usage)?;
        let offset = match opts.get("offset") {
            Some(t) if t.text != "auto" => Some(parse_u64(t, "a particle id offset (a whole number, or `auto`)")?),
            _ => None,
        };
        let file = SourceFile::read(&self.input_path(&s[1]), Some(&s[1]))?;
        let parsed = parse_topology(&file)?;
        let mut top = match self.setup.topology.take() {
            None if offset.unwrap_or(0) == 0 => {
                self.setup.topology = Some(Arc::new(parsed));
                return Ok(());
            }
            previous => previous.map(Arc::unwrap_or_clone).unwrap_or_default(),
        };
        top.append_at(parsed, offset).map_err(|c| {
            s[1].error(format!(
                "particle id {} of `{}` plus offset {} is already used by an earlier topology; expected `offset auto` or an offset >= {}",
                c.id, s[1].text, c.offset, c.used
            ))
        })?;
        self.setup.topology = Some(Arc::new(top));
        Ok(())
    }
}
