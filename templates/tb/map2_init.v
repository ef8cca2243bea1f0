
{%- for f in t.map2_params %}
    $readmemh({= f.param =}, map2, {= f.first =}, {= f.last =});
{%- endfor %}
    for (k = 0; k < NWRITES; k = k + 1) begin
      wi = k[A+1:0];
      if (^map2[wi] === 1'bx) $fatal(1, "{= t.map2_pattern =}: entry %0d is missing or not hex", k);
    end
    nwr = 0;
