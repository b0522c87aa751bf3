console.log("swarmsim viewer");
