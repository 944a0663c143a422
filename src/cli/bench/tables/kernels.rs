//! Table 2's analogue for `tables`: the instructions, texture fetches and
//! address arithmetic of each kernel the paper counts, from its optimised
//! SPIR-V (glslangValidator, when installed).

use super::report::KernelCount;

/// Counts the instructions of a kernel's optimised SPIR-V (glslangValidator -Os).
fn spirv_counts(
    vertex: Option<&str>,
    fragment: &str,
    defines: &[(&str, String)],
) -> Result<(usize, usize, usize), String> {
    let dir = std::env::temp_dir().join(format!("photonmap-spirv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).map_err(|e| e.to_string())?;
    let mut totals = (0, 0, 0);
    for (stage, name) in vertex
        .map(|v| ("vert", v))
        .into_iter()
        .chain([("frag", fragment)])
    {
        let src = photonmap::gpu::program::preprocessed_source(name, defines)
            .ok_or("missing GLSL file")?;
        let path = dir.join(format!("kernel.{stage}"));
        std::fs::write(&path, src).map_err(|e| e.to_string())?;
        let out = std::process::Command::new("glslangValidator")
            .args(["-G", "--aml", "--amb", "-Os", "-H", "-S", stage])
            .arg(&path)
            .arg("-o")
            .arg(dir.join("kernel.spv"))
            .output()
            .map_err(|_| {
                "glslangValidator is not installed (apt-get install glslang-tools)".to_string()
            })?;
        if !out.status.success() {
            return Err(format!(
                "glslangValidator failed on glsl/{name}: {}",
                String::from_utf8_lossy(&out.stdout)
                    .lines()
                    .last()
                    .unwrap_or("")
            ));
        }
        let text = String::from_utf8_lossy(&out.stdout);
        let mut in_function = false;
        for line in text.lines() {
            let op = line
                .split_whitespace()
                .find(|w| w.chars().next().is_some_and(|c| c.is_ascii_uppercase()))
                .unwrap_or("");
            if op == "Function" {
                in_function = true;
                continue;
            }
            if op == "FunctionEnd" {
                in_function = false;
            }
            if !in_function
                || matches!(
                    op,
                    "" | "Label"
                        | "SelectionMerge"
                        | "LoopMerge"
                        | "Variable"
                        | "Phi"
                        | "FunctionParameter"
                )
            {
                continue;
            }
            totals.0 += 1;
            totals.1 += usize::from(
                op.starts_with("ImageFetch") || op.starts_with("ImageSample") || op == "ImageRead",
            );
            let integer_op = matches!(
                op,
                "IAdd"
                    | "ISub"
                    | "IMul"
                    | "SDiv"
                    | "UDiv"
                    | "SMod"
                    | "SRem"
                    | "UMod"
                    | "BitwiseAnd"
                    | "BitwiseOr"
                    | "BitwiseXor"
                    | "ShiftLeftLogical"
                    | "ShiftRightLogical"
                    | "ShiftRightArithmetic"
                    | "ConvertFToS"
                    | "ConvertSToF"
            );
            totals.2 += usize::from(integer_op);
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
    Ok(totals)
}

pub(super) fn table2() -> Result<Vec<KernelCount>, String> {
    let routed = vec![("ROUTED", "1".to_string())];
    // (name, vertex program, fragment program, defines, the paper's counts)
    type Kernel<'a> = (
        &'a str,
        Option<&'a str>,
        &'a str,
        Vec<(&'a str, String)>,
        [usize; 4],
    );
    let kernels: [Kernel; 5] = [
        (
            "Bitonic Sort",
            None,
            "photon/bitonic.frag",
            vec![],
            [52, 2, 13, 0],
        ),
        (
            "Binary Search",
            None,
            "photon/binary_search.frag",
            vec![],
            [18, 1, 13, 0],
        ),
        (
            "Rad. Estimate (sorted map)",
            None,
            "render/knn_search.frag",
            vec![],
            [202, 6, 47, 41],
        ),
        (
            "Stencil Routing",
            Some("photon/route.vert"),
            "photon/route.frag",
            vec![],
            [42, 0, 25, 0],
        ),
        (
            "Rad. Estimate (routed map)",
            None,
            "render/knn_search.frag",
            routed,
            [193, 5, 20, 41],
        ),
    ];
    kernels
        .into_iter()
        .map(|(kernel, vertex, fragment, defines, paper)| {
            let (instructions, texture_fetches, address_arithmetic) =
                spirv_counts(vertex, fragment, &defines)?;
            Ok(KernelCount {
                kernel: kernel.into(),
                instructions,
                texture_fetches,
                address_arithmetic,
                packing: 0,
                paper,
            })
        })
        .collect()
}
