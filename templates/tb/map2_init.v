
    $readmemh({= t.map2_params[0] =}, map2, 0, MAP_ENTRIES - 1);
    $readmemh({= t.map2_params[1] =}, map2, MAP_ENTRIES, 2 * MAP_ENTRIES - 1);
    $readmemh({= t.map2_params[2] =}, map2, 2 * MAP_ENTRIES, 3 * MAP_ENTRIES - 1);
    for (k = 0; k < NWRITES; k = k + 1) begin
      wi = k[A+1:0];
      if (^map2[wi] === 1'bx) $fatal(1, "{= t.map2_pattern =}: entry %0d is missing or not hex", k);
    end
    nwr = 0;
