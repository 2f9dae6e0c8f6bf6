// csg.wgsl — the one evaluator of fray-geometry's postfix CSG program (words in `indices`: a
// leaf's global index above the op code, or max, min, negation), a template the include step
// instantiates once per algebra (`// #instantiate "csg.wgsl" { NAME: …; T: …; … }`):
//   csg_{{NAME}}(first word, word count, {{PARAMS}}) → {{T}}
// with {{LEAF}}(word, {{ARGS}}) a leaf's value, {{NEG}}(v) its negation and
// {{COMBINE}}(is_max, a, b) the max (union) or min (intersection) of two — the point value, the
// interval bound with its sign-slope rule, and the value-gradient-leaf of normals all run this
// one loop (as fray-geometry runs its one program evaluator over several algebras).

fn csg_{{NAME}}(first: u32, count: u32, {{PARAMS}}) -> {{T}} {
    if count == 1u {
        return {{LEAF}}(indices[first], {{ARGS}});
    }
    var stack: array<{{T}}, MAX_STACK>;
    var top = 0u;
    for (var w = first; w < first + count; w++) {
        let word = indices[w];
        let op = word & ((1u << OP_BITS) - 1u);
        if op == OP_LEAF {
            stack[top] = {{LEAF}}(word, {{ARGS}});
            top++;
        } else if op == OP_NEG {
            stack[top - 1u] = {{NEG}}(stack[top - 1u]);
        } else {
            let b = stack[top - 1u];
            let a = stack[top - 2u];
            top--;
            stack[top - 1u] = {{COMBINE}}(op == OP_MAX, a, b);
        }
    }
    return stack[0];
}
