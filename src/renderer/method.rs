//! [`Method`]: the shading methods by name, checked when the program is compiled rather than
//! when a frame runs.

use std::fmt;
use std::str::FromStr;

use crate::Error;

/// A shading method ([`Renderer::set_method`](crate::Renderer::set_method)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum Method {
    /// Every light for every fragment: the reference the others are tested against.
    Forward,
    /// Light lists per 2D screen tile.
    Tiled,
    /// Light lists per cell of a cascaded 3D grid (the default).
    #[default]
    Clustered,
    /// A G-buffer, then the lights as screen-space volumes (ES 3.0).
    Deferred,
    /// Forward for few lights, clustered for many, chosen per frame; deferred (else forward)
    /// for a frame with more visible lights than clustered indexes.
    Auto,
}

impl Method {
    /// Every method, in the order of `manylight info`.
    pub const ALL: [Method; 5] = [
        Method::Forward,
        Method::Tiled,
        Method::Clustered,
        Method::Deferred,
        Method::Auto,
    ];

    /// Its name in the method table and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            Method::Forward => "forward",
            Method::Tiled => "tiled",
            Method::Clustered => "clustered",
            Method::Deferred => "deferred",
            Method::Auto => "auto",
        }
    }
}

impl fmt::Display for Method {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Method {
    type Err = Error;

    /// A name as `--method` takes it; an unknown one is [`Error::UnknownMethod`].
    fn from_str(name: &str) -> Result<Method, Error> {
        Method::ALL
            .into_iter()
            .find(|m| m.name() == name)
            .ok_or_else(|| Error::UnknownMethod {
                name: name.to_string(),
                available: Method::ALL.map(Method::name).join(", "),
            })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_method_of_the_table_has_a_variant_and_back() {
        let table: Vec<&str> = crate::methods::METHODS.iter().map(|m| m.name).collect();
        let variants: Vec<&str> = Method::ALL.iter().map(|m| m.name()).collect();
        assert_eq!(table, variants);
        assert_eq!(Method::default().name(), crate::methods::DEFAULT_METHOD);
        for m in Method::ALL {
            assert_eq!(m.name().parse::<Method>().unwrap(), m);
        }
        assert!(matches!(
            "forwrad".parse::<Method>(),
            Err(Error::UnknownMethod { .. })
        ));
    }
}
