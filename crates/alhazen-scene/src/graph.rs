//! The scene graph of the TOML format (course, §"Scene graphs": a DAG of nodes with
//! transforms, shared subgraphs, parametrised objects and level of detail).
//!
//! `[groups.NAME]` holds `[[groups.NAME.object]]` entries — objects, or instances of other
//! groups — optional `parameters` (defaults) and optional `lod` (levels chosen by projected
//! size). An object `{ group = "NAME", transform, parameters }` instances it anywhere, any
//! number of times; inside the group, a value `"$p"` stands for parameter `p`. The graph is
//! expanded into the model's flat object list, each object with its composed transform; mesh
//! files are loaded once, so every instance of a big mesh shares it (one BVH per mesh). A cycle
//! is refused naming its path.

use crate::did_you_mean;
use crate::model::{CameraDesc, Object};
use crate::parse::Parser;
use crate::reader::{Node, R, Table};
use alhazen_math::{Transform, Vec3};
use std::collections::HashMap;
use std::rc::Rc;

/// Groups nest at most this deep (a DAG deeper than this is surely a mistake).
const MAX_DEPTH: usize = 64;

/// The scene's group definitions by name.
pub(crate) struct Groups<'a, 'i> {
    by_name: HashMap<&'a str, Node<'a, 'i>>,
}

impl<'a, 'i> Groups<'a, 'i> {
    pub(crate) fn of(top: &Table<'a, 'i>) -> R<Self> {
        let mut by_name = HashMap::new();
        if let Some(n) = top.get("groups") {
            let t = n.table_any()?;
            for (name, _) in t.keys() {
                let g = t.get(name).expect("key listed");
                g.table(&["parameters", "object", "lod"])?;
                by_name.insert(name, g);
            }
        }
        Ok(Self { by_name })
    }
}

impl Parser<'_> {
    /// An `[[object]]` entry as the objects it stands for: itself, or a group's expansion.
    pub(crate) fn objects_of<'a, 'i>(
        &mut self,
        n: &Node<'a, 'i>,
        groups: &Groups<'a, 'i>,
        path: &mut Vec<&'a str>,
        parent: Transform,
    ) -> R<Vec<Object>> {
        let t = n.table_any()?;
        let Some(g) = t.get("group") else {
            let mut o = self.object(n, 0)?;
            o.transform = parent * o.transform;
            return Ok(vec![o]);
        };
        t.check_keys(&["group", "name", "transform", "parameters"])?;
        let own = match t.get("transform") {
            Some(tr) => crate::parse::transform(&tr)?,
            None => Transform::IDENTITY,
        };
        self.instance(&g, t.get("parameters"), groups, path, parent * own)
    }

    /// Group `name_node` instanced with `transform` and the instance's `parameters`.
    fn instance<'a, 'i>(
        &mut self,
        name_node: &Node<'a, 'i>,
        parameters: Option<Node<'a, 'i>>,
        groups: &Groups<'a, 'i>,
        path: &mut Vec<&'a str>,
        transform: Transform,
    ) -> R<Vec<Object>> {
        let name = name_node.str()?;
        let Some(group) = groups.by_name.get(name) else {
            let mut d = name_node.err(format!("unknown group \"{name}\"; define it under [groups.{name}]"));
            if let Some(s) = did_you_mean(name, groups.by_name.keys().copied()) {
                *d = d.with_help(format!("did you mean \"{s}\"?"));
            }
            return Err(d);
        };
        if path.contains(&name) {
            let cycle: Vec<&str> = path.iter().skip_while(|g| **g != name).copied().chain([name]).collect();
            return Err(name_node.err(format!("the groups form a cycle: {}", cycle.join(" → "))));
        }
        if path.len() >= MAX_DEPTH {
            return Err(name_node.err(format!("groups nested deeper than {MAX_DEPTH} levels")));
        }
        let scope = scope_of(group, parameters.as_ref(), name)?;
        let gt = Table { scope: scope.clone(), ..group.table_any()? };
        path.push(name);
        let mut out = vec![];
        if let Some(lod) = gt.get("lod") {
            let level = self.level_of_detail(&lod, transform)?;
            out.extend(self.instance(&level, parameters.clone(), groups, path, transform)?);
        }
        for n in gt.get("object").map(|n| n.array()).transpose()?.unwrap_or_default() {
            out.extend(self.objects_of(&n, groups, path, transform)?);
        }
        path.pop();
        Ok(out)
    }

    /// `lod = { radius = r, levels = [{ group = "fine", min_pixels = 200 }, …, { group = "coarse" }] }`:
    /// the first level whose `min_pixels` the instance's bounding sphere (radius `r` in the
    /// group's units) covers on the image, else the last.
    fn level_of_detail<'a, 'i>(&mut self, lod: &Node<'a, 'i>, transform: Transform) -> R<Node<'a, 'i>> {
        let t = lod.table(&["radius", "levels"])?;
        let radius = t.req("radius")?.positive()?;
        let levels = t.req("levels")?.array()?;
        if levels.is_empty() {
            return Err(t.req("levels")?.err("`levels` needs at least one { group = … }"));
        }
        let scale = [Vec3::X, Vec3::Y, Vec3::Z].map(|a| transform.vector(a).length()).into_iter().fold(0.0, f64::max);
        let pixels = self.projected_pixels(transform.point(Vec3::ZERO), radius * scale);
        for level in &levels {
            let l = level.table(&["group", "min_pixels"])?;
            let min = l.get("min_pixels").map_or(Ok(0.0), |n| n.non_negative())?;
            if pixels >= min {
                return l.req("group");
            }
        }
        levels.last().expect("not empty").table_any()?.req("group")
    }

    /// How many pixels (of the image's height) a sphere of `radius` at `center` spans.
    fn projected_pixels(&self, center: Vec3, radius: f64) -> f64 {
        let (w, h) = (self.scene.render.width as f64, self.scene.render.height as f64);
        let perspective = |eye: Vec3, tan_half: f64| {
            let d = (center - eye).length().max(1e-12);
            2.0 * radius / d * h / (2.0 * tan_half)
        };
        match &self.scene.camera {
            CameraDesc::Perspective { look, opening, .. } => {
                let f = opening.frustum(w / h, None);
                perspective(look.eye, (f.t - f.b) / (2.0 * f.n))
            }
            CameraDesc::Orthographic { width, .. } | CameraDesc::Axonometric { width, .. } => 2.0 * radius / width * w,
            CameraDesc::Stereo { look, screen_distance, screen_width, .. } => {
                perspective(look.eye, screen_width * h / w / (2.0 * screen_distance))
            }
            CameraDesc::Panorama { look, angle } => perspective(look.eye, (angle / 2.0).tan().abs().max(1e-6) * h / w),
        }
    }
}

/// The group's parameter defaults overridden by the instance's values (resolved where the
/// instance stands).
fn scope_of<'a, 'i>(group: &Node<'a, 'i>, given: Option<&Node<'a, 'i>>, name: &str) -> R<crate::reader::Scope<'a, 'i>> {
    let gt = group.table_any()?;
    let mut map = HashMap::new();
    if let Some(d) = gt.get("parameters") {
        let d = d.table_any()?;
        for (k, _) in d.keys() {
            map.insert(k.to_string(), d.get(k).expect("key listed"));
        }
    }
    if let Some(p) = given {
        let p = p.table_any()?;
        for (k, span) in p.keys() {
            if !map.contains_key(k) {
                let mut known: Vec<&String> = map.keys().collect();
                known.sort();
                let list = known.iter().map(|k| format!("`{k}`")).collect::<Vec<_>>().join(", ");
                let mut d = p.src.error(span, format!("group \"{name}\" has no parameter `{k}` (it has: {list})"));
                if let Some(s) = did_you_mean(k, map.keys().map(String::as_str)) {
                    *d = d.with_help(format!("did you mean `{s}`?"));
                }
                return Err(d);
            }
            map.insert(k.to_string(), p.get(k).expect("key listed"));
        }
    }
    Ok((!map.is_empty()).then(|| Rc::new(map)))
}
