//! A directive's parameters by name and type, as pbrt-v4 reads them: each
//! getter checks the declared type, and `finish` refuses any parameter no
//! getter asked for (pbrt-v4 refuses unused parameters too).

use std::cell::Cell;
use std::path::Path;

use glam::DVec3;

use super::super::source::Cx;
use super::lexer::{Param, Val};
use crate::error::SceneError;

pub struct Params<'a> {
    pub list: Vec<Param>,
    used: Vec<Cell<bool>>,
    pub file: &'a Path,
    /// The directive and its type, for messages: `Shape "sphere"`.
    pub what: String,
    pub line: usize,
}

/// A colour parameter: an RGB triple, or what photonmap cannot take.
pub enum Colour {
    Rgb([f64; 3]),
    /// A blackbody temperature, K.
    Blackbody(f64),
    /// A named or sampled spectrum, or a texture.
    Other(String),
}

impl<'a> Params<'a> {
    /// Something of this directive photonmap cannot render (`detail`, after
    /// the directive's name): refused at its line, or under --lenient noted
    /// as becoming `instead`.
    pub fn unsupported(&self, cx: &mut Cx, detail: &str, instead: &str) -> Result<(), SceneError> {
        cx.unsupported(
            self.file,
            self.line,
            &format!("{} {detail}", self.what),
            instead,
        )
    }

    pub fn new(list: Vec<Param>, file: &'a Path, what: String, line: usize) -> Self {
        let used = list.iter().map(|_| Cell::new(false)).collect();
        Params {
            list,
            used,
            file,
            what,
            line,
        }
    }

    pub fn err(&self, line: usize, field: &str, message: String) -> SceneError {
        SceneError::new(self.file, line, &format!("{} {field}", self.what), message)
    }

    /// The parameter `name`, of one of `types`, marked used.
    pub fn find(&self, name: &str, types: &[&str]) -> Result<Option<&Param>, SceneError> {
        let Some(i) = self.list.iter().position(|p| p.name == name) else {
            return Ok(None);
        };
        self.used[i].set(true);
        let p = &self.list[i];
        if !types.contains(&p.ty.as_str()) {
            return Err(self.err(
                p.line,
                name,
                format!(
                    "is declared \"{}\"; it must be {}",
                    p.ty,
                    types.join(" or ")
                ),
            ));
        }
        Ok(Some(p))
    }

    /// Whether the parameter is given (marks it used).
    pub fn has(&self, name: &str) -> bool {
        match self.list.iter().position(|p| p.name == name) {
            Some(i) => {
                self.used[i].set(true);
                true
            }
            None => false,
        }
    }

    pub fn line_of(&self, name: &str) -> usize {
        self.list
            .iter()
            .find(|p| p.name == name)
            .map_or(self.line, |p| p.line)
    }

    /// All the numbers of a parameter, `per` at a time.
    pub fn nums(
        &self,
        name: &str,
        types: &[&str],
        per: usize,
    ) -> Result<Option<Vec<f64>>, SceneError> {
        let Some(p) = self.find(name, types)? else {
            return Ok(None);
        };
        let v: Vec<f64> = p
            .values
            .iter()
            .map(|v| match v {
                Val::Num(x) => Ok(*x),
                _ => Err(self.err(p.line, name, format!("\"{} {name}\" takes numbers", p.ty))),
            })
            .collect::<Result<_, _>>()?;
        if v.is_empty() || !v.len().is_multiple_of(per) {
            return Err(self.err(
                p.line,
                name,
                format!("has {} numbers; it takes a multiple of {per}", v.len()),
            ));
        }
        Ok(Some(v))
    }

    pub fn float(&self, name: &str, default: f64) -> Result<f64, SceneError> {
        Ok(match self.nums(name, &["float"], 1)? {
            Some(v) if v.len() == 1 => v[0],
            Some(_) => return Err(self.err(self.line_of(name), name, "takes one number".into())),
            None => default,
        })
    }

    pub fn int(&self, name: &str, default: i64) -> Result<i64, SceneError> {
        Ok(match self.nums(name, &["integer"], 1)? {
            Some(v) if v.len() == 1 && v[0].fract() == 0.0 && v[0].abs() < 1e15 => v[0] as i64,
            Some(_) => return Err(self.err(self.line_of(name), name, "takes one integer".into())),
            None => default,
        })
    }

    pub fn ints(&self, name: &str) -> Result<Option<Vec<i64>>, SceneError> {
        let Some(v) = self.nums(name, &["integer"], 1)? else {
            return Ok(None);
        };
        if v.iter().any(|x| x.fract() != 0.0 || *x < 0.0 || *x > 1e15) {
            return Err(self.err(
                self.line_of(name),
                name,
                "takes integers of 0 or more".into(),
            ));
        }
        Ok(Some(v.into_iter().map(|x| x as i64).collect()))
    }

    /// Points, vectors or normals: `types` as pbrt-v4 and v3 spell them.
    pub fn vec3s(&self, name: &str, types: &[&str]) -> Result<Option<Vec<DVec3>>, SceneError> {
        Ok(self
            .nums(name, types, 3)?
            .map(|v| v.chunks(3).map(|c| DVec3::new(c[0], c[1], c[2])).collect()))
    }

    pub fn string(&self, name: &str) -> Result<Option<String>, SceneError> {
        let Some(p) = self.find(name, &["string", "texture"])? else {
            return Ok(None);
        };
        match p.values.as_slice() {
            [Val::Str(s)] => Ok(Some(s.clone())),
            _ => Err(self.err(p.line, name, "takes one quoted string".into())),
        }
    }

    pub fn bool(&self, name: &str, default: bool) -> Result<bool, SceneError> {
        let Some(p) = self.find(name, &["bool"])? else {
            return Ok(default);
        };
        match p.values.as_slice() {
            [Val::Bool(b)] => Ok(*b),
            [Val::Str(s)] if s == "true" || s == "false" => Ok(s == "true"),
            _ => Err(self.err(p.line, name, "takes true or false".into())),
        }
    }

    /// A colour (rgb, blackbody, spectrum, or a texture's name).
    pub fn colour(&self, name: &str) -> Result<Option<Colour>, SceneError> {
        let Some(p) = self.find(
            name,
            &["rgb", "color", "blackbody", "spectrum", "texture", "float"],
        )?
        else {
            return Ok(None);
        };
        let nums: Vec<f64> = p
            .values
            .iter()
            .filter_map(|v| if let Val::Num(x) = v { Some(*x) } else { None })
            .collect();
        let all_nums = nums.len() == p.values.len();
        Ok(Some(match (p.ty.as_str(), nums.len()) {
            ("rgb" | "color", 3) if all_nums => {
                if nums.iter().any(|&c| c < 0.0) {
                    return Err(self.err(p.line, name, "an rgb value is negative".into()));
                }
                Colour::Rgb([nums[0], nums[1], nums[2]])
            }
            ("float", 1) if all_nums && nums[0] >= 0.0 => Colour::Rgb([nums[0]; 3]),
            ("blackbody", 1) if all_nums && nums[0] > 0.0 => Colour::Blackbody(nums[0]),
            ("rgb" | "color" | "blackbody" | "float", _) => {
                return Err(self.err(
                    p.line,
                    name,
                    format!("\"{} {name}\" has the wrong number of values", p.ty),
                ))
            }
            (ty, _) => Colour::Other(format!("\"{ty} {name}\"")),
        }))
    }

    /// Refuses a parameter no getter asked for.
    pub fn finish(&self) -> Result<(), SceneError> {
        match self.list.iter().zip(&self.used).find(|(_, u)| !u.get()) {
            Some((p, _)) => Err(self.err(
                p.line,
                &p.name,
                format!("unknown parameter \"{} {}\"", p.ty, p.name),
            )),
            None => Ok(()),
        }
    }

    /// Marks parameters read but ignored (they change nothing photonmap draws).
    pub fn ignore(&self, names: &[&str]) {
        for n in names {
            self.has(n);
        }
    }
}

/// The linear sRGB colour of a blackbody at `kelvin`, scaled to luminance 1
/// (pbrt-v4 normalises a blackbody emitter so): the CIE 1931 chromaticity
/// of Planck's law by Kim et al.'s cubic fit (1667 K to 25000 K, clamped).
pub fn blackbody_rgb(kelvin: f64) -> [f64; 3] {
    let t = kelvin.clamp(1667.0, 25000.0);
    let x = if t <= 4000.0 {
        -0.2661239e9 / t.powi(3) - 0.2343589e6 / t.powi(2) + 0.8776956e3 / t + 0.179910
    } else {
        -3.0258469e9 / t.powi(3) + 2.1070379e6 / t.powi(2) + 0.2226347e3 / t + 0.240390
    };
    let y = if t <= 2222.0 {
        -1.1063814 * x.powi(3) - 1.34811020 * x.powi(2) + 2.18555832 * x - 0.20219683
    } else if t <= 4000.0 {
        -0.9549476 * x.powi(3) - 1.37418593 * x.powi(2) + 2.09137015 * x - 0.16748867
    } else {
        3.0817580 * x.powi(3) - 5.87338670 * x.powi(2) + 3.75112997 * x - 0.37001483
    };
    let (cx, cz) = (x / y, (1.0 - x - y) / y);
    let r = 3.2404542 * cx - 1.5371385 - 0.4985314 * cz;
    let g = -0.9692660 * cx + 1.8760108 + 0.0415560 * cz;
    let b = 0.0556434 * cx - 0.2040259 + 1.0572252 * cz;
    [r.max(0.0), g.max(0.0), b.max(0.0)]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn blackbody_of_6500_k_is_nearly_white() {
        let c = blackbody_rgb(6504.0);
        assert!(c.iter().all(|&v| (v - 1.0).abs() < 0.06), "{c:?}");
        let warm = blackbody_rgb(2700.0);
        assert!(warm[0] > warm[1] && warm[1] > warm[2], "{warm:?}");
    }
}
